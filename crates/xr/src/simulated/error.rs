//! Why a simulated headset's script could not be used.

use std::path::PathBuf;

use incise_sim::ron_file::{ReadError, SyntaxError};

/// A script that could not be read, parsed or used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScriptError {
    /// The file could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// RON syntax, unknown field, wrong type: ron's position and message.
    #[error(transparent)]
    Syntax(#[from] SyntaxError),
    /// A value parsed but cannot be used.
    #[error("{path}: {field}: {msg}")]
    Value {
        /// The script file.
        path: PathBuf,
        /// The field, e.g. `head[1].t`.
        field: String,
        /// What is wrong, with the offending value.
        msg: String,
    },
}

impl ScriptError {
    /// The value of `field` in the script `path` cannot be used: `msg`.
    pub fn value(path: &std::path::Path, field: &str, msg: String) -> Self {
        ScriptError::Value {
            path: path.into(),
            field: field.into(),
            msg,
        }
    }
}
