//! What an exercise file says: the scene, the planned incision, the target depth and its
//! tolerance band, the time limit and the pass thresholds (`config/exercises/*.ron`).

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A training exercise as written in its RON file. Lengths in metres, forces in newtons,
/// times in seconds.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Exercise {
    /// Short name used in results and the history.
    pub name: String,
    /// One or two sentences for the trainee: what to cut and what to avoid.
    #[serde(default)]
    pub description: String,
    /// Scene file (with a scalpel), relative to the exercise file.
    pub scene: String,
    /// The planned incision: a polyline on the organ's rest surface, m (≥ 2 points).
    pub plan: Vec<Vec3>,
    /// Target depth of the cut below the surface along the whole plan, m.
    pub depth: f32,
    /// The tolerance band around the plan.
    pub tolerance: Tolerance,
    /// How far a plan point may lie from the organ's surface before the file is refused,
    /// m (each point is then projected onto the surface).
    #[serde(default = "default_surface_tolerance")]
    pub surface_tolerance: f32,
    /// Time allowed from the first to the last blade contact, s.
    pub time_limit: f32,
    /// What an attempt must reach to pass.
    pub pass: PassThresholds,
}

fn default_surface_tolerance() -> f32 {
    0.002
}

/// The band around the plan inside which released tissue counts as the intended cut.
#[derive(Debug, Clone, Copy, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Tolerance {
    /// Largest distance from the plan along the surface, m.
    pub lateral: f32,
    /// Largest depth error (either way) from the target depth, m.
    pub depth: f32,
}

/// Pass thresholds; every one must hold (docs/scoring.md).
#[derive(Debug, Clone, Copy, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PassThresholds {
    /// Smallest fraction of the plan's length that must be cut (0..1).
    pub completion: f32,
    /// Largest mean distance of the cut's surface trace from the plan, m.
    pub mean_deviation: f32,
    /// Largest distance of any point of the surface trace from the plan, m.
    pub max_deviation: f32,
    /// Largest mean |depth − target| along the cut part of the plan, m.
    pub depth_error: f32,
    /// Largest volume of tissue cut outside the tolerance band (released tets, or the tets a
    /// cut surface bounds there), m³.
    pub collateral: f32,
    /// Largest contact force on the blade, N.
    pub max_force: f32,
    /// Smallest overall score (0..100).
    pub score: f32,
}
