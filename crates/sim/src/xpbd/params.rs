//! Solver settings and errors.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::TetProjection;
use crate::contact::{ContactError, CutZone};
use crate::material::HydrostaticStiffness;

/// Settings of the XPBD small-steps solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverParams {
    /// Frame time step, s (60 Hz by default).
    pub frame_dt: f32,
    /// Substeps per frame (one constraint iteration each, PHYSICS.md §1.2).
    pub substeps: u32,
    /// Gravity, m/s² (z is up).
    pub gravity: Vec3,
    /// Velocity damping rate, 1/s: `v ← v·max(0, 1 − damping·h)` each substep.
    pub damping: f32,
    /// How a tet's two constraints are projected.
    pub projection: TetProjection,
    /// Stiffness of the hydrostatic constraint: `Lambda` (PHYSICS.md, default) or
    /// `LambdaPlusMu` (small-strain response matches E and ν exactly).
    pub hydrostatic: HydrostaticStiffness,
    /// Worker threads for the coloured projection: 0 = all cores, 1 = serial.
    pub threads: usize,
    /// von Mises stress above which a tet is released, Pa; `None` disables cutting.
    pub release_threshold: Option<f32>,
    /// Where the stress criterion may release tets: `Anywhere` (tearing) or
    /// `NearEdge(reach: m)` (only where a cutting sphere passed).
    pub cut_zone: CutZone,
    /// Frames a live tet may stay inverted before the run stops with an error.
    pub max_inverted_frames: u32,
}

impl Default for SolverParams {
    fn default() -> Self {
        SolverParams {
            frame_dt: 1.0 / 60.0,
            substeps: 10,
            gravity: Vec3::new(0.0, 0.0, -9.81),
            damping: 1.0,
            projection: TetProjection::Coupled,
            hydrostatic: HydrostaticStiffness::Lambda,
            threads: 0,
            release_threshold: None,
            cut_zone: CutZone::Anywhere,
            max_inverted_frames: 30,
        }
    }
}

impl SolverParams {
    /// Substep length `h = frame_dt / substeps`.
    pub fn substep(&self) -> f32 {
        self.frame_dt / self.substeps as f32
    }

    /// Check ranges; the message names the field.
    pub fn validate(&self) -> Result<(), SolverError> {
        let bad = |field: &'static str, msg: String| Err(SolverError::BadParameter { field, msg });
        if !(self.frame_dt.is_finite() && self.frame_dt > 0.0 && self.frame_dt <= 0.1) {
            return bad(
                "frame_dt",
                format!("must be in (0, 0.1] s, got {}", self.frame_dt),
            );
        }
        if self.substeps == 0 || self.substeps > 10_000 {
            return bad(
                "substeps",
                format!("must be 1..=10000, got {}", self.substeps),
            );
        }
        if !self.gravity.is_finite() {
            return bad("gravity", format!("must be finite, got {}", self.gravity));
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return bad("damping", format!("must be >= 0 1/s, got {}", self.damping));
        }
        if let Some(t) = self.release_threshold {
            if !(t.is_finite() && t > 0.0) {
                return bad(
                    "release_threshold",
                    format!("must be a positive stress in Pa, got {t}"),
                );
            }
        }
        if let CutZone::NearEdge { reach } = self.cut_zone {
            if !(reach.is_finite() && reach >= 0.0) {
                return bad(
                    "cut_zone.reach",
                    format!("must be a length >= 0 m, got {reach}"),
                );
            }
        }
        Ok(())
    }
}

/// Why the solver refused to start or stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SolverError {
    /// A setting is out of range.
    #[error("solver.{field} {msg}")]
    BadParameter {
        /// Field name.
        field: &'static str,
        /// What is wrong.
        msg: String,
    },
    /// The material is unusable.
    #[error("material: {0}")]
    Material(#[from] crate::material::MaterialError),
    /// A node position became NaN or infinite; the frame was rolled back.
    #[error(
        "frame {frame}: node {node} has a non-finite position (tet {tet} is one of its tets); the frame was rolled back"
    )]
    NonFinite {
        /// Frame index (0-based) that failed.
        frame: u64,
        /// First offending node.
        node: usize,
        /// A tet containing that node.
        tet: usize,
    },
    /// A live tet stayed inverted for too long; the frame was rolled back.
    #[error(
        "frame {frame}: tet {tet} has stayed inverted for {frames} frames (det F = {det}); the frame was rolled back"
    )]
    Inverted {
        /// Frame index (0-based) that failed.
        frame: u64,
        /// Offending tet.
        tet: usize,
        /// Consecutive inverted frames.
        frames: u32,
        /// Its current det F.
        det: f32,
    },
    /// The substep is too long for this material and mesh: the solve would be unstable.
    #[error(
        "substep {h_ms:.3} ms is too long for this material and mesh: tet {tet} has stiffness number {kappa:.2} (stable up to {max}); use at least {needed} substeps per frame, coarser tets or a softer material"
    )]
    Unstable {
        /// Substep length, ms.
        h_ms: f32,
        /// The worst tet.
        tet: usize,
        /// Its stiffness number.
        kappa: f32,
        /// The accepted bound.
        max: f32,
        /// Substeps per frame that would satisfy the bound.
        needed: u32,
    },
    /// The tool cannot be used.
    #[error(transparent)]
    Tool(#[from] ContactError),
    /// The GPU device failed while stepping (device lost, readback failed).
    #[error("GPU: {0}")]
    Device(String),
    /// The thread pool could not be created.
    #[error("could not start {threads} solver threads: {msg}")]
    ThreadPool {
        /// Requested threads.
        threads: usize,
        /// Cause.
        msg: String,
    },
}
