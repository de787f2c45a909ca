//! Reading RON files: the two errors every RON-configured part of incise reports, a file
//! that cannot be read (`file: OS error`) and text that does not parse
//! (`file:line:col: ron's message`), written once for the sim, the scalpel and the app.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

/// A file that could not be read: `file: OS error`. The OS error is part of the message,
/// not a separate cause, so an error chain prints it once.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {error}")]
pub struct ReadError {
    /// The file.
    pub path: PathBuf,
    /// OS error.
    pub error: std::io::Error,
}

/// RON syntax, unknown field, wrong type: `file:line:col: message`, ron's position and
/// message.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path}:{line}:{col}: {msg}")]
pub struct SyntaxError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub col: usize,
    /// ron's message (names the field).
    pub msg: String,
}

impl SyntaxError {
    /// ron's error `e`, placed in the file `path`.
    pub fn new(path: &Path, e: ron::error::SpannedError) -> Self {
        SyntaxError {
            path: path.into(),
            line: e.span.start.line,
            col: e.span.start.col,
            msg: e.code.to_string(),
        }
    }
}

/// Read the file `path` to a string, naming it on failure.
pub fn read(path: &Path) -> Result<String, ReadError> {
    std::fs::read_to_string(path).map_err(|error| ReadError {
        path: path.into(),
        error,
    })
}

/// Parse RON `text`; `path` names it in errors.
pub fn parse<T: DeserializeOwned>(text: &str, path: &Path) -> Result<T, SyntaxError> {
    ron::from_str(text).map_err(|e| SyntaxError::new(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn syntax_error_names_file_line_and_column() {
        let e = parse::<(u32, u32)>("(1,\n 2 3)", Path::new("a.ron")).expect_err("no comma");
        assert_eq!((e.line, e.col), (2, 4), "{e}");
        assert!(e.to_string().starts_with("a.ron:2:4: "), "{e}");
    }

    #[test]
    fn read_error_names_the_file() {
        let e = read(Path::new("/nonexistent/incise.ron")).expect_err("missing");
        assert!(
            e.to_string().starts_with("/nonexistent/incise.ron: "),
            "{e}"
        );
    }
}
