//! Errors: a bad value names its dotted field; a bad file adds the file and its line (and
//! column, for syntax errors), as `src/scene/load.rs` does for scenes.

use std::path::PathBuf;

use incise_sim::ron_file::{ReadError, SyntaxError};

/// A value that parsed but cannot be used, named by its dotted field path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {msg}")]
pub struct FieldError {
    /// Dotted field path, e.g. `poses[3].rotation`.
    pub field: String,
    /// What is wrong, with the offending value.
    pub msg: String,
}

impl FieldError {
    /// An error for `field`.
    pub fn new(field: impl Into<String>, msg: impl Into<String>) -> Self {
        FieldError {
            field: field.into(),
            msg: msg.into(),
        }
    }
}

/// Why a tool or stroke file could not be read, used or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileError {
    /// The file could not be read.
    #[error(transparent)]
    Io(#[from] ReadError),
    /// RON syntax, unknown field, wrong type: ron's position and message.
    #[error(transparent)]
    Syntax(#[from] SyntaxError),
    /// A value parsed but is out of range.
    #[error("{path}:{line}: {field}: {msg}")]
    Value {
        /// The file.
        path: PathBuf,
        /// 1-based line of the field (0 if it could not be found in the text).
        line: usize,
        /// Dotted field path.
        field: String,
        /// What is wrong.
        msg: String,
    },
    /// The file could not be written (the message names the file).
    #[error("{0}")]
    Write(#[source] incise_sim::MeshError),
    /// The value could not be turned into RON text.
    #[error("{path}: cannot write RON: {msg}")]
    Serialize {
        /// The file.
        path: PathBuf,
        /// ron's message.
        msg: String,
    },
}
