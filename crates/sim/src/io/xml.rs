//! A minimal XML tag scanner, enough for VTK XML files: tags, attributes, comments,
//! declarations and CDATA, with line numbers for errors. No entities, no namespaces.

use std::cell::Cell;
use std::path::Path;

use super::text::quote;
use crate::MeshError;

/// Whether a tag opens, closes, or is self-closing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TagKind {
    /// `<name ...>`
    Start,
    /// `</name>`
    End,
    /// `<name .../>`
    Empty,
}

/// One XML tag: name, attributes (values as written, not unescaped) and its byte span.
#[derive(Debug)]
pub struct Tag<'a> {
    /// The tag name.
    pub name: &'a str,
    /// Start, end or self-closing.
    pub kind: TagKind,
    /// `(key, value)` pairs in order.
    pub attrs: Vec<(&'a str, &'a str)>,
    /// Byte offset of the `<`.
    pub start: usize,
    /// Byte offset just past the `>`.
    pub end: usize,
}

impl<'a> Tag<'a> {
    /// The value of attribute `key`, if present.
    pub fn attr(&self, key: &str) -> Option<&'a str> {
        self.attrs.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
    }
}

/// A forward-only scanner over the tags of an XML text.
#[derive(Debug)]
pub struct Scanner<'a> {
    text: &'a str,
    origin: &'a Path,
    pos: usize,
    /// (byte offset, line there), for incremental line counting.
    line_cache: Cell<(usize, usize)>,
}

impl<'a> Scanner<'a> {
    /// A scanner at the start of `text`, read from `origin`.
    pub fn new(text: &'a str, origin: &'a Path) -> Self {
        Self {
            text,
            origin,
            pos: 0,
            line_cache: Cell::new((0, 1)),
        }
    }

    /// The path errors name.
    pub fn origin(&self) -> &'a Path {
        self.origin
    }

    /// 1-based line of byte offset `pos` (cheap when offsets grow).
    pub fn line_at(&self, pos: usize) -> usize {
        let pos = pos.min(self.text.len());
        let (at, line) = self.line_cache.get();
        let bytes = self.text.as_bytes();
        let count = |a: usize, b: usize| bytes[a..b].iter().filter(|&&b| b == b'\n').count();
        let line = if pos >= at {
            line + count(at, pos)
        } else {
            1 + count(0, pos)
        };
        self.line_cache.set((pos, line));
        line
    }

    /// A parse error at `line`.
    pub fn error(&self, line: usize, message: impl Into<String>) -> MeshError {
        MeshError::parse(self.origin, line, message)
    }

    /// The end-of-file error: what was expected, at the last line (0 for an empty text).
    pub fn eof_error(&self, what: &str) -> MeshError {
        let newlines = self.line_at(self.text.len()) - 1;
        let line = if self.text.is_empty() || self.text.ends_with('\n') {
            newlines
        } else {
            newlines + 1
        };
        if self.text.trim().is_empty() {
            self.error(line, format!("the file is empty; expected {what}"))
        } else {
            self.error(line, format!("unexpected end of file: expected {what}"))
        }
    }

    /// Skip past `end`, searching from `from`; an unterminated construct is an error.
    fn skip_past(&mut self, from: usize, end: &str, opened_at: usize) -> Result<(), MeshError> {
        match self.text[from..].find(end) {
            Some(i) => {
                self.pos = from + i + end.len();
                Ok(())
            }
            None => Err(self.error(
                self.line_at(opened_at),
                format!("this markup is never closed with {}", quote(end)),
            )),
        }
    }

    /// The text up to the closing tag `close` (e.g. `</DataArray`), and its start offset;
    /// the scanner moves past the closing tag.
    pub fn content_until(
        &mut self,
        close: &str,
        line: usize,
    ) -> Result<(&'a str, usize), MeshError> {
        let start = self.pos;
        let Some(i) = self.text[start..].find(close) else {
            return Err(self.error(line, format!("this element is never closed with {close}>")));
        };
        let content = &self.text[start..start + i];
        self.skip_past(start + i, ">", start + i)?;
        Ok((content, start))
    }

    /// The next tag, skipping text, comments, declarations and CDATA; `None` at the end.
    pub fn next_tag(&mut self) -> Result<Option<Tag<'a>>, MeshError> {
        let bytes = self.text.as_bytes();
        loop {
            let Some(rel) = self.text[self.pos..].find('<') else {
                self.pos = self.text.len();
                return Ok(None);
            };
            let start = self.pos + rel;
            let rest = &self.text[start..];
            if rest.starts_with("<!--") {
                self.skip_past(start + 4, "-->", start)?;
                continue;
            }
            if rest.starts_with("<![CDATA[") {
                self.skip_past(start, "]]>", start)?;
                continue;
            }
            if rest.starts_with("<?") {
                self.skip_past(start, "?>", start)?;
                continue;
            }
            if rest.starts_with("<!") {
                self.skip_past(start, ">", start)?;
                continue;
            }
            let closing = rest.starts_with("</");
            let mut i = start + if closing { 2 } else { 1 };
            let name_start = i;
            while i < bytes.len() && !bytes[i].is_ascii_whitespace() && !b"/>".contains(&bytes[i]) {
                i += 1;
            }
            let name = &self.text[name_start..i];
            let bad =
                |sc: &Self, why: &str| sc.error(sc.line_at(start), format!("malformed tag: {why}"));
            if name.is_empty() {
                return Err(bad(self, "a tag name must follow '<'"));
            }
            let mut attrs = Vec::new();
            let kind = loop {
                while i < bytes.len() && bytes[i].is_ascii_whitespace() {
                    i += 1;
                }
                match bytes.get(i) {
                    None => return Err(bad(self, &format!("<{name} is never closed with '>'"))),
                    Some(b'>') => {
                        i += 1;
                        break if closing {
                            TagKind::End
                        } else {
                            TagKind::Start
                        };
                    }
                    Some(b'/') if bytes.get(i + 1) == Some(&b'>') && !closing => {
                        i += 2;
                        break TagKind::Empty;
                    }
                    Some(_) if closing => {
                        return Err(bad(self, &format!("unexpected text in </{name}>")));
                    }
                    Some(_) => {}
                }
                let key_start = i;
                while i < bytes.len()
                    && !bytes[i].is_ascii_whitespace()
                    && !b"=/>".contains(&bytes[i])
                {
                    i += 1;
                }
                let key = &self.text[key_start..i];
                while i < bytes.len() && bytes[i].is_ascii_whitespace() {
                    i += 1;
                }
                if key.is_empty() || bytes.get(i) != Some(&b'=') {
                    return Err(bad(
                        self,
                        &format!("expected attribute=\"value\" in <{name}>"),
                    ));
                }
                i += 1;
                while i < bytes.len() && bytes[i].is_ascii_whitespace() {
                    i += 1;
                }
                let quote_char = match bytes.get(i) {
                    Some(&q @ (b'"' | b'\'')) => q,
                    _ => return Err(bad(self, &format!("the value of {key} must be quoted"))),
                };
                let value_start = i + 1;
                let Some(len) = bytes[value_start..].iter().position(|&b| b == quote_char) else {
                    return Err(bad(self, &format!("the value of {key} is never closed")));
                };
                attrs.push((key, &self.text[value_start..value_start + len]));
                i = value_start + len + 1;
            };
            self.pos = i;
            return Ok(Some(Tag {
                name,
                kind,
                attrs,
                start,
                end: i,
            }));
        }
    }
}

/// `text` escaped for use inside a double-quoted XML attribute.
pub fn escape_attr(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tags(text: &str) -> Result<Vec<(String, TagKind, usize)>, MeshError> {
        let mut sc = Scanner::new(text, Path::new("x.xml"));
        let mut out = Vec::new();
        while let Some(tag) = sc.next_tag()? {
            out.push((tag.name.to_string(), tag.kind, sc.line_at(tag.start)));
        }
        Ok(out)
    }

    #[test]
    fn tags_attributes_and_lines() {
        let text = "<?xml version=\"1.0\"?>\n<!-- a <b> comment\n-->\n<A k=\"v>w\" j = 'x'>\n text <B/>\n</A>";
        let got = tags(text).expect("well formed");
        let names: Vec<_> = got.iter().map(|(n, k, l)| (n.as_str(), *k, *l)).collect();
        assert_eq!(
            names,
            vec![
                ("A", TagKind::Start, 4),
                ("B", TagKind::Empty, 5),
                ("A", TagKind::End, 6)
            ]
        );
        let mut sc = Scanner::new(text, Path::new("x.xml"));
        let a = sc.next_tag().ok().flatten().expect("tag A");
        assert_eq!(
            (a.attr("k"), a.attr("j"), a.attr("z")),
            (Some("v>w"), Some("x"), None)
        );
    }

    #[test]
    fn content_until_returns_the_body_and_skips_the_end_tag() {
        let text = "<D>1 2\n3</D><E/>";
        let mut sc = Scanner::new(text, Path::new("x.xml"));
        let d = sc.next_tag().ok().flatten().expect("D");
        let (body, start) = sc.content_until("</D", 1).expect("closed");
        assert_eq!((body, start, d.end), ("1 2\n3", 3, 3));
        assert_eq!(sc.next_tag().ok().flatten().map(|t| t.name), Some("E"));
        let mut sc = Scanner::new("<D>\n1 2", Path::new("x.xml"));
        let _ = sc.next_tag();
        let err = sc.content_until("</D", 1).expect_err("unclosed");
        assert!(
            err.to_string()
                .contains("x.xml:1: this element is never closed"),
            "{err}"
        );
    }

    #[test]
    fn malformed_tags_name_their_line() {
        for (text, want) in [
            (
                "\n<A k=v>",
                "x.xml:2: malformed tag: the value of k must be quoted",
            ),
            (
                "<A\n\n k=\"v",
                "x.xml:1: malformed tag: the value of k is never closed",
            ),
            (
                "\n\n< A>",
                "x.xml:3: malformed tag: a tag name must follow '<'",
            ),
            (
                "<A k>",
                "x.xml:1: malformed tag: expected attribute=\"value\" in <A>",
            ),
            ("</A x>", "x.xml:1: malformed tag: unexpected text in </A>"),
            ("<A", "x.xml:1: malformed tag: <A is never closed with '>'"),
            (
                "\n<!-- open",
                "x.xml:2: this markup is never closed with \"-->\"",
            ),
        ] {
            let err = tags(text).expect_err(text).to_string();
            assert_eq!(err, want, "{text:?}");
        }
    }

    #[test]
    fn escape_attr_escapes_markup() {
        assert_eq!(
            escape_attr("a<b>&\"c'\n"),
            "a&lt;b&gt;&amp;&quot;c&apos;&#10;"
        );
    }
}
