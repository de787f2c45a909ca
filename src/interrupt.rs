//! Ctrl-C (SIGINT) and SIGTERM as a request to stop: a run finishes the frame in hand,
//! writes its report, stroke and snapshots, and exits 130; an XR session ends through
//! the runtime's own shutdown. A second signal while the first is being honoured kills
//! the process as usual.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Exit status of a run stopped by Ctrl-C (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Route Ctrl-C and SIGTERM to [`requested`]; the first signal is honoured gracefully,
/// a second one terminates at once. Calling it again does nothing.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        if REQUESTED.swap(true, Ordering::SeqCst) {
            std::process::exit(EXIT_INTERRUPTED as i32);
        }
        eprintln!("\nstopping after this frame (Ctrl-C again to quit at once)");
    });
}

/// Whether a stop was requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// The error a run stopped by Ctrl-C ends with (exit status [`EXIT_INTERRUPTED`]).
#[derive(Debug, thiserror::Error)]
#[error("{what} interrupted after {frames} frames (output so far kept in {out})")]
pub struct Interrupted {
    /// What was interrupted (the scene file).
    pub what: String,
    /// Frames completed.
    pub frames: u64,
    /// Output folder.
    pub out: String,
}
