//! What `incise preview` is asked to open, and where its exercise attempts are saved.

use std::path::PathBuf;

use crate::exercise::LiveExercise;
use crate::pictures::run_pictures::RunPictures;
use crate::pictures::screenshots::ImageSize;
use crate::sim_body::DeviceChoice;

/// An exercise open in the preview, its attempts' pictures taken offscreen.
pub type PreviewExercise = LiveExercise<RunPictures>;

/// Options of `incise preview`.
#[derive(Debug, Clone)]
pub struct PreviewOptions {
    /// Scene to open.
    pub scene: PathBuf,
    /// Render this many frames, then exit.
    pub frames: Option<u64>,
    /// Save the window's last frame here (PNG) when exiting.
    pub screenshot: Option<PathBuf>,
    /// Where the solver runs (auto: the render device's GPU when it is not a software one).
    pub device: DeviceChoice,
    /// Window size.
    pub size: ImageSize,
    /// Open this exercise (its scene instead of `scene`).
    pub exercise: Option<PathBuf>,
}

/// Where the preview saves exercise attempts, one folder each.
pub const ATTEMPTS_DIR: &str = "out/exercises";

/// The results history preview attempts are appended to (`incise exercise`'s default).
pub const HISTORY_FILE: &str = "results/history.jsonl";
