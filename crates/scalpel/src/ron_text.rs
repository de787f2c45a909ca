//! Placing value errors in RON text: the line a dotted field path (`poses[3].rotation`,
//! `spheres.radius`) sits on. Reading and syntax errors are `incise_sim::ron_file`'s.

use std::path::Path;

use crate::error::{FieldError, FileError};

/// A field error placed in the file: its line found from the field path.
pub(crate) fn value_error(text: &str, path: &Path, e: FieldError) -> FileError {
    FileError::Value {
        path: path.into(),
        line: field_line(text, &e.field),
        field: e.field,
        msg: e.msg,
    }
}

/// 1-based line of the dotted field path `field` in RON `text`; 0 when not found.
///
/// Each component `name` is found as the next `name:` after the previous component; an
/// index `name[i]` then walks to the start of the list's element `i`. Comments are
/// skipped. When a later component cannot be found, the line of the last one found is
/// returned.
pub(crate) fn field_line(text: &str, field: &str) -> usize {
    let code = blank_comments(text);
    let bytes = code.as_bytes();
    let mut pos = 0usize;
    let mut found = false;
    for component in field.split('.') {
        let (name, index) = split_index(component);
        let Some(key) = find_key(&code, name, pos) else {
            break;
        };
        pos = key;
        found = true;
        if let Some(i) = index {
            match list_element(bytes, pos, i) {
                Some(p) => pos = p,
                None => break,
            }
        }
    }
    if !found {
        return 0;
    }
    1 + bytes[..pos].iter().filter(|&&b| b == b'\n').count()
}

/// `name[3]` → (`name`, Some(3)); `name` → (`name`, None).
fn split_index(component: &str) -> (&str, Option<usize>) {
    if let Some(open) = component.find('[') {
        let index = component[open + 1..]
            .trim_end_matches(']')
            .parse::<usize>()
            .ok();
        (&component[..open], index)
    } else {
        (component, None)
    }
}

/// Byte offset just after `name:` (a whole identifier followed by optional spaces and a
/// colon) at or after `from`.
fn find_key(code: &str, name: &str, from: usize) -> Option<usize> {
    let bytes = code.as_bytes();
    let mut start = from;
    while let Some(rel) = code.get(start..)?.find(name) {
        let at = start + rel;
        let end = at + name.len();
        let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
        let before_ok = at == 0 || !ident(bytes[at - 1]);
        let mut after = end;
        while after < bytes.len() && bytes[after].is_ascii_whitespace() {
            after += 1;
        }
        let after_ok = end == bytes.len() || !ident(bytes[end]);
        if before_ok && after_ok && after < bytes.len() && bytes[after] == b':' {
            return Some(after + 1);
        }
        start = end;
    }
    None
}

/// Byte offset of the first non-space character of element `index` of the list that
/// opens at the first `[` at or after `from`.
fn list_element(bytes: &[u8], from: usize, index: usize) -> Option<usize> {
    let open = from + bytes[from..].iter().position(|&b| b == b'[')?;
    let mut depth = 0i32;
    let mut element = 0usize;
    let mut in_string = false;
    let mut element_start = Some(open + 1);
    let mut i = open;
    while i < bytes.len() {
        let b = bytes[i];
        if in_string {
            if b == b'\\' {
                i += 1;
            } else if b == b'"' {
                in_string = false;
            }
        } else {
            match b {
                b'"' => in_string = true,
                b'[' | b'(' | b'{' => depth += 1,
                b']' | b')' | b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        return None;
                    }
                }
                b',' if depth == 1 => {
                    element += 1;
                    element_start = Some(i + 1);
                }
                _ => {}
            }
        }
        if element == index
            && let Some(s) = element_start
        {
            let skip = bytes[s..].iter().position(|b| !b.is_ascii_whitespace())?;
            return Some(s + skip);
        }
        i += 1;
    }
    None
}

/// `text` with `//` comments replaced by spaces (same byte offsets and lines).
fn blank_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        let mut in_string = false;
        let mut cut = None;
        let b = line.as_bytes();
        let mut i = 0;
        while i < b.len() {
            match b[i] {
                b'\\' if in_string => i += 1,
                b'"' => in_string = !in_string,
                b'/' if !in_string && b.get(i + 1) == Some(&b'/') => {
                    cut = Some(i);
                    break;
                }
                _ => {}
            }
            i += 1;
        }
        match cut {
            Some(c) => {
                out.push_str(&line[..c]);
                out.extend(
                    line[c..]
                        .chars()
                        .map(|ch| if ch == '\n' { '\n' } else { ' ' }),
                );
            }
            None => out.push_str(line),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "(\n    // poses: not here\n    poses: [\n        (t: 0.0, rotation: (0, 0, 0, 1)),\n        (t: 1.0,\n         rotation: (0, 0, 0, 1)),\n        (t: 2.0, rotation: (0, 0, 0, 1)),\n    ],\n    spheres: Fixed(count: 0, radius: 1.0),\n)";

    #[test]
    fn finds_indexed_and_nested_fields() {
        assert_eq!(field_line(TEXT, "poses"), 3);
        assert_eq!(field_line(TEXT, "poses[0]"), 4);
        assert_eq!(field_line(TEXT, "poses[1].t"), 5);
        assert_eq!(field_line(TEXT, "poses[1].rotation"), 6);
        assert_eq!(field_line(TEXT, "poses[2].rotation"), 7);
        assert_eq!(field_line(TEXT, "spheres.count"), 9);
        assert_eq!(field_line(TEXT, "nothing"), 0);
        // A missing index falls back to the list's line.
        assert_eq!(field_line(TEXT, "poses[7].t"), 3);
    }
}
