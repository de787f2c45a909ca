//! What `incise run` is asked to do and what it produced.

use std::path::PathBuf;

use crate::pictures::plan_decal::PlanDecal;
use crate::pictures::screenshots::ImageSize;
use crate::report::Report;
use crate::sim_body::DeviceChoice;
use crate::sim_body::RestCut;

/// Frames between checkpoints of report.json and the recorded stroke (1 s at 60 Hz).
pub const CHECKPOINT_FRAMES: u64 = 60;

/// Options of `incise run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Scene file.
    pub scene: PathBuf,
    /// Frames to run (default: the scene's duration).
    pub frames: Option<u64>,
    /// Output folder.
    pub out: PathBuf,
    /// Write a .vtu every K frames (0 = none).
    pub vtu_every: u64,
    /// Solver threads (default: the scene's, 0 = all cores).
    pub threads: Option<usize>,
    /// Suppress progress output.
    pub quiet: bool,
    /// Where the solver runs.
    pub device: DeviceChoice,
    /// Write an offscreen `frame_NNNNN.png` every K frames (0 = none).
    pub screenshot_every: u64,
    /// Size of those screenshots.
    pub screenshot_size: ImageSize,
    /// Run a mass-spring scene's local loop on its own thread at this rate, Hz (the
    /// haptic-rate option, PHYSICS.md §2.6); `None`: the ordinary frame loop.
    pub haptic_rate: Option<f64>,
    /// Drive the scene's tool with this stroke file instead of the scene's stroke.
    pub stroke: Option<PathBuf>,
    /// Record the tool's pose at every frame to this stroke file (replayable with
    /// `--stroke`, bit for bit).
    pub record_stroke: Option<PathBuf>,
    /// Replay the free nodes of each localised frame of the Nakao run that wrote this
    /// report.json (`--replay-localisation`) instead of choosing them.
    pub replay_localisation: Option<PathBuf>,
    /// Fault injection for tests: lose the GPU device just before this frame.
    pub inject_gpu_loss_at: Option<u64>,
    /// Fault injection for tests: a NaN velocity on the first free node before this frame.
    pub inject_nan_at: Option<u64>,
    /// Draw this planned incision on the screenshots (exercise runs; Xpbd scenes).
    pub screenshot_decal: Option<PlanDecal>,
}

/// What a finished run produced.
#[derive(Debug)]
pub struct RunOutcome {
    /// Path of report.json.
    pub report_path: PathBuf,
    /// The report.
    pub report: Report,
    /// What the body cut, at rest (for scoring an exercise; `None`: its method does not
    /// cut, or a haptic thread held its state).
    pub rest_cut: Option<RestCut>,
}
