//! A line-numbered tokenizer shared by the text readers.
//!
//! A [`Cursor`] walks the content lines of a text (empty lines and comments skipped),
//! either line by line ([`Cursor::next_line`], which yields [`Fields`]) or as one stream of
//! whitespace-separated tokens across lines ([`Cursor::value`]). Every error it makes is a
//! [`MeshError::Parse`] naming the origin path and the 1-based line; at the end of the text
//! the error names the last line and what was expected.

use std::fmt::Display;
use std::path::Path;
use std::str::{FromStr, SplitWhitespace};

use crate::MeshError;

/// Longest token quoted verbatim in an error message.
const MAX_QUOTED: usize = 40;

/// Read a whole file as text; bytes that are not UTF-8 become U+FFFD (and then fail to parse).
pub fn read_text(path: &Path) -> Result<String, MeshError> {
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    })
}

/// `token` quoted for an error message, shortened when long.
pub fn quote(token: &str) -> String {
    match token.char_indices().nth(MAX_QUOTED) {
        Some((cut, _)) => format!("{:?}...", &token[..cut]),
        None => format!("{token:?}"),
    }
}

/// A cursor over the content lines of a text, with line numbers.
#[derive(Debug, Clone)]
pub struct Cursor<'a> {
    origin: &'a Path,
    lines: std::str::Lines<'a>,
    comment: Option<char>,
    next_number: usize,
    last_line: usize,
    current: Option<Fields<'a>>,
}

impl<'a> Cursor<'a> {
    /// A cursor over `text`, read from `origin`; `comment` starts a comment to end of line.
    pub fn new(text: &'a str, origin: &'a Path, comment: Option<char>) -> Self {
        Self::starting_at(text, origin, comment, 1)
    }

    /// Like [`Cursor::new`] for a text whose first line is line `first_line` of `origin`.
    pub fn starting_at(
        text: &'a str,
        origin: &'a Path,
        comment: Option<char>,
        first_line: usize,
    ) -> Self {
        Self {
            origin,
            lines: text.lines(),
            comment,
            next_number: first_line,
            last_line: first_line.saturating_sub(1),
            current: None,
        }
    }

    /// The path errors name.
    pub fn origin(&self) -> &'a Path {
        self.origin
    }

    /// Number of the last line read (0 before any).
    pub fn last_line(&self) -> usize {
        self.last_line
    }

    /// The next line as it is, empty or not, with its number; `None` at the end.
    pub fn raw_line(&mut self) -> Option<(usize, &'a str)> {
        self.current = None;
        let text = self.lines.next()?;
        let number = self.next_number;
        self.next_number += 1;
        self.last_line = number;
        Some((number, text))
    }

    /// The next line with content (comments stripped), as fields; `None` at the end.
    pub fn next_line(&mut self) -> Option<Fields<'a>> {
        while let Some((number, raw)) = self.raw_line() {
            let text = match self.comment.and_then(|c| raw.find(c)) {
                Some(cut) => &raw[..cut],
                None => raw,
            }
            .trim();
            if !text.is_empty() {
                return Some(Fields::new(self.origin, number, text));
            }
        }
        None
    }

    /// The next content line; at the end, an error saying `what` was expected.
    pub fn expect_line(&mut self, what: impl Display) -> Result<Fields<'a>, MeshError> {
        self.next_line().ok_or_else(|| self.eof_error(what))
    }

    /// The next token, continuing the current line and then the following ones.
    pub fn next_token(&mut self) -> Option<Token<'a>> {
        loop {
            if let Some(fields) = &mut self.current {
                if let Some(text) = fields.iter.next() {
                    return Some(Token {
                        text,
                        line: fields.line,
                    });
                }
            }
            let fields = self.next_line()?;
            self.current = Some(fields);
        }
    }

    /// The next token; at the end, an error saying `what` was expected.
    pub fn token(&mut self, what: impl Display) -> Result<Token<'a>, MeshError> {
        self.next_token().ok_or_else(|| self.eof_error(what))
    }

    /// The next token if it is on the current line (the one the last token came from).
    pub fn next_on_line(&mut self) -> Option<Token<'a>> {
        let fields = self.current.as_mut()?;
        let text = fields.iter.next()?;
        Some(Token {
            text,
            line: fields.line,
        })
    }

    /// The next token without consuming it; `None` at the end.
    pub fn peek(&mut self) -> Option<&'a str> {
        loop {
            if let Some(fields) = &self.current {
                if let Some(text) = fields.iter.clone().next() {
                    return Some(text);
                }
            }
            let fields = self.next_line()?;
            self.current = Some(fields);
        }
    }

    /// The next token parsed as `T`, with the line it is on.
    pub fn value<T: FromStr>(&mut self, what: impl Display) -> Result<(T, usize), MeshError> {
        let token = self.token(&what)?;
        Ok((token.parse(self.origin, what)?, token.line))
    }

    /// Drop the rest of the current line, so that the next token starts a new line.
    pub fn end_line(&mut self) {
        self.current = None;
    }

    /// An error at `line` of the origin.
    pub fn error(&self, line: usize, message: impl Into<String>) -> MeshError {
        MeshError::parse(self.origin, line, message)
    }

    /// The end-of-file error: what was expected, at the last line.
    pub fn eof_error(&self, what: impl Display) -> MeshError {
        let message = if self.last_line == 0 {
            format!("the file is empty; expected {what}")
        } else {
            format!("unexpected end of file: expected {what}")
        };
        MeshError::parse(self.origin, self.last_line, message)
    }
}

/// One token and the line it is on.
#[derive(Debug, Clone, Copy)]
pub struct Token<'a> {
    /// The token text.
    pub text: &'a str,
    /// Its 1-based line.
    pub line: usize,
}

impl Token<'_> {
    /// Parse as `T`; the error says `what` was expected and quotes the token.
    pub fn parse<T: FromStr>(&self, origin: &Path, what: impl Display) -> Result<T, MeshError> {
        self.text.parse().map_err(|_| {
            MeshError::parse(
                origin,
                self.line,
                format!("expected {what}, found {}", quote(self.text)),
            )
        })
    }
}

/// The whitespace-separated fields of one content line.
#[derive(Debug, Clone)]
pub struct Fields<'a> {
    origin: &'a Path,
    line: usize,
    text: &'a str,
    iter: SplitWhitespace<'a>,
}

impl<'a> Fields<'a> {
    /// The fields of `text`, which is line `line` of `origin`.
    pub fn new(origin: &'a Path, line: usize, text: &'a str) -> Self {
        Self {
            origin,
            line,
            text,
            iter: text.split_whitespace(),
        }
    }

    /// The 1-based line number.
    pub fn line(&self) -> usize {
        self.line
    }

    /// The whole line, trimmed and without its comment.
    pub fn text(&self) -> &'a str {
        self.text
    }

    /// The next field as text; the error says `what` was expected.
    pub fn next_str(&mut self, what: impl Display) -> Result<&'a str, MeshError> {
        self.iter
            .next()
            .ok_or_else(|| self.error(format!("expected {what}, found the end of the line")))
    }

    /// The next field parsed as `T`; the error says `what` was expected and quotes it.
    pub fn next<T: FromStr>(&mut self, what: impl Display) -> Result<T, MeshError> {
        let text = self.next_str(&what)?;
        Token {
            text,
            line: self.line,
        }
        .parse(self.origin, what)
    }

    /// The fields not read yet.
    pub fn rest(&mut self) -> SplitWhitespace<'a> {
        self.iter.clone()
    }

    /// An error at this line.
    pub fn error(&self, message: impl Into<String>) -> MeshError {
        MeshError::parse(self.origin, self.line, message)
    }

    /// An error at this line saying that `what` was expected instead of the whole line.
    pub fn unexpected(&self, what: impl Display) -> MeshError {
        self.error(format!("expected {what}, found {}", quote(self.text)))
    }
}

/// Room to reserve for `count` items announced by a header, bounded by what `text` can hold
/// so that a bogus count cannot exhaust memory: a node, element or vertex line takes at
/// least 8 bytes (`"1 0 0 0\n"`), so a file of n bytes holds at most n/8 + 1 of them.
/// (A reservation is only a hint: more items still fit, the vector grows.)
pub fn capacity(count: u64, text: &str) -> usize {
    usize::try_from(count)
        .unwrap_or(usize::MAX)
        .min(text.len() / 8 + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn origin() -> &'static Path {
        Path::new("mem.txt")
    }

    #[test]
    fn lines_skip_blanks_and_comments_and_keep_numbers() {
        let text = "# header\n\n  a 1 # note\n\t\nb 2\n";
        let mut c = Cursor::new(text, origin(), Some('#'));
        let mut l = c.next_line().expect("line 3");
        assert_eq!((l.line(), l.text()), (3, "a 1"));
        assert_eq!(l.next_str("a name").ok(), Some("a"));
        assert_eq!(l.next::<u32>("a number").ok(), Some(1));
        assert_eq!(c.next_line().map(|l| l.line()), Some(5));
        assert!(c.next_line().is_none());
        assert_eq!(c.last_line(), 5);
    }

    #[test]
    fn typed_field_error_quotes_token_and_line() {
        let mut c = Cursor::new("\n\nx abc\n", origin(), None);
        let mut l = c.expect_line("a node").expect("a line");
        let _ = l.next_str("a tag");
        let err = l.next::<u64>("a node index").expect_err("abc is no index");
        assert_eq!(
            err.to_string(),
            "mem.txt:3: expected a node index, found \"abc\""
        );
        let err = l.next::<u64>("a node index").expect_err("line is over");
        assert!(
            err.to_string()
                .contains(":3: expected a node index, found the end")
        );
    }

    #[test]
    fn token_stream_crosses_lines_and_eof_names_last_line() {
        let mut c = Cursor::new("1 2\n\n3\n\n", origin(), None);
        let got: Vec<(u8, usize)> = (0..3).filter_map(|_| c.value("a value").ok()).collect();
        assert_eq!(got, vec![(1, 1), (2, 1), (3, 3)]);
        let err = c.value::<u8>("a fourth value").expect_err("end");
        assert_eq!(
            err.to_string(),
            "mem.txt:4: unexpected end of file: expected a fourth value"
        );
    }

    #[test]
    fn peek_does_not_consume_and_end_line_drops_rest() {
        let mut c = Cursor::new("a b\nc", origin(), None);
        assert_eq!(c.peek(), Some("a"));
        assert_eq!(c.token("x").map(|t| t.text).ok(), Some("a"));
        c.end_line();
        assert_eq!(c.peek(), Some("c"));
        assert_eq!(c.token("x").map(|t| t.line).ok(), Some(2));
        assert_eq!(c.peek(), None);
    }

    #[test]
    fn empty_text_error_says_so_at_line_zero() {
        let mut c = Cursor::new("", origin(), Some('#'));
        let err = c.expect_line("a header").expect_err("empty");
        assert_eq!(
            err.to_string(),
            "mem.txt:0: the file is empty; expected a header"
        );
    }

    #[test]
    fn offset_cursor_numbers_from_first_line() {
        let mut c = Cursor::starting_at(" 7\n8 x", origin(), None, 10);
        assert_eq!(c.value::<u8>("v").ok(), Some((7, 10)));
        assert_eq!(c.value::<u8>("v").ok(), Some((8, 11)));
        let err = c.value::<u8>("a value").expect_err("x");
        assert!(err.to_string().starts_with("mem.txt:11: expected a value"));
    }

    #[test]
    fn long_tokens_are_shortened_in_messages() {
        let long = "é".repeat(100);
        let q = quote(&long);
        assert!(q.ends_with("...") && q.chars().count() < 50, "{q}");
    }

    #[test]
    fn capacity_is_bounded_by_text() {
        assert_eq!(capacity(u64::MAX, "abcd"), 1);
        assert_eq!(capacity(u64::MAX, &"x".repeat(800)), 101);
        assert_eq!(capacity(1, "abcd"), 1);
    }
}
