//! How a run ends: the report's status and error written, and the outcome or the error
//! that names the scene (exit 1) or the interruption (exit 130).

use std::path::PathBuf;

use anyhow::{Result, bail};

use super::options::{RunOptions, RunOutcome};
use crate::report::Report;
use crate::sim_body::RestCut;

/// Why a run stopped before its last frame.
#[derive(Debug, Clone)]
pub enum RunEnd {
    /// The solver failed (the error).
    Failed(String),
    /// Ctrl-C or SIGTERM after this many frames.
    Interrupted {
        /// Frames completed.
        frames: u64,
    },
}

/// Record how the run ended in `report` ("completed", "failed" with the error, or
/// "interrupted"), write it, and return the outcome with the body's `rest_cut`; after a failure, the error naming
/// the scene and saying that the output written so far is kept; after Ctrl-C, an
/// [`Interrupted`](crate::interrupt::Interrupted) error (exit 130).
pub fn finish(
    mut report: Report,
    report_path: PathBuf,
    stopped: Option<RunEnd>,
    opts: &RunOptions,
    rest_cut: Option<RestCut>,
) -> Result<RunOutcome> {
    let (status, error) = match &stopped {
        None => ("completed", None),
        Some(RunEnd::Failed(e)) => ("failed", Some(e.clone())),
        Some(RunEnd::Interrupted { frames }) => (
            "interrupted",
            Some(format!("interrupted by the user after {frames} frames")),
        ),
    };
    report.status = status.into();
    report.error = error;
    report.write(&report_path)?;
    match stopped {
        None => Ok(RunOutcome {
            report_path,
            report,
            rest_cut,
        }),
        Some(RunEnd::Failed(e)) => bail!(
            "{}: {e} (output so far kept in {})",
            opts.scene.display(),
            opts.out.display()
        ),
        Some(RunEnd::Interrupted { frames }) => Err(crate::interrupt::Interrupted {
            what: opts.scene.display().to_string(),
            frames,
            out: opts.out.display().to_string(),
        }
        .into()),
    }
}
