//! What `result.json` holds: the exercise, the attempt's measurements and its verdict.

use serde::Serialize;

use super::metrics::Metrics;
use super::model::{PassThresholds, Tolerance};
use super::score::Verdict;
use crate::scene::Method;

/// Everything `result.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct ExerciseResult {
    /// Exercise name.
    pub exercise: String,
    /// The simulation method of the exercise's scene ("xpbd" or "nakao").
    pub method: Method,
    /// Exercise file.
    pub exercise_file: String,
    /// The exercise's description.
    pub description: String,
    /// Scene file.
    pub scene_file: String,
    /// Stroke file.
    pub stroke_file: String,
    /// Device the solver ran on.
    pub device: String,
    /// When it was scored, UTC.
    pub time: String,
    /// Frames simulated.
    pub frames: u64,
    /// The plan projected onto the organ's rest surface, m.
    pub plan: Vec<[f64; 3]>,
    /// Target depth, m.
    pub target_depth: f32,
    /// Tolerance band.
    pub tolerance: Tolerance,
    /// Time limit, s.
    pub time_limit: f32,
    /// Pass thresholds.
    pub thresholds: PassThresholds,
    /// The measurements.
    pub metrics: Metrics,
    /// Score and checks.
    pub verdict: Verdict,
}
