//! Solver settings and errors.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{ConstraintPair, TetProjection};
use crate::contact::{ContactError, CutZone};
use crate::implicit::{CoarseError, Scheme};
use crate::material::{HydrostaticStiffness, Material};
use crate::stress::StressMeasure;

/// Default interval of the release check in simulation time, s (240 Hz).
pub const DEFAULT_RELEASE_INTERVAL: f32 = 1.0 / 240.0;

/// How the CPU solver evaluates the tet projections.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CpuKernel {
    /// Eight tets of a colour at once in SIMD lanes, for the rest-free coupled pair (the
    /// other pairs and modes run scalar): sixteen (two blocks) in AVX-512 registers where
    /// the CPU has AVX-512F, else in AVX registers where it has AVX2 (detected at run
    /// time), the same bits either way; matches `Scalar` to rounding (tested).
    #[default]
    Lanes,
    /// The lanes in AVX registers even where the CPU has AVX-512 (AVX2 detected at run
    /// time, else the build's own): for measuring what AVX-512 buys, and the path of an
    /// AVX2-only CPU on an AVX-512 one. The same bits as `Lanes`.
    Avx2Lanes,
    /// The same lanes at the build's own instruction set, no run-time detection (SSE2 in
    /// the portable x86-64 build): for measuring what AVX2 buys.
    PortableLanes,
    /// One tet at a time: the reference the lanes and the GPU are tested against.
    Scalar,
}

/// In which order the CPU projects one sweep's tets (PHYSICS.md §1.2, parallel form).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CpuSweep {
    /// One pass per colour over the whole mesh, the threads synchronising after each: the
    /// reference order, which the GPU follows too.
    #[default]
    Coloured,
    /// The mesh in fixed slabs (`xpbd/sweep_plan.rs`): each slab's tets colour after
    /// colour by one task, then the tets across slabs; four synchronisations a sweep. The
    /// GPU follows it with one dispatch per phase (a workgroup per slab or cut) instead of
    /// one per colour. Another Gauss–Seidel order: the same converged answer, not the same
    /// rounding.
    Blocks,
}

/// Settings of the XPBD small-steps solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverParams {
    /// How a frame is advanced: `Xpbd` small steps (default) or `Newton(..)` implicit
    /// Euler steps (`crate::implicit`).
    pub scheme: Scheme,
    /// Frame time step, s (60 Hz by default).
    pub frame_dt: f32,
    /// Substeps per frame (one constraint iteration each, PHYSICS.md §1.2).
    pub substeps: u32,
    /// Gravity, m/s² (z is up).
    pub gravity: Vec3,
    /// Velocity damping rate, 1/s: `v ← v·max(0, 1 − damping·h)` each substep.
    pub damping: f32,
    /// Which Neo-Hookean constraint pair: `RestFree` (default) or the seed's
    /// `GammaShifted`.
    pub constraints: ConstraintPair,
    /// How a tet's two constraints are projected.
    pub projection: TetProjection,
    /// Stiffness of the γ-shifted pair's hydrostatic constraint: `Lambda` (PHYSICS.md,
    /// default) or `LambdaPlusMu` (small-strain response matches E and ν exactly). The
    /// rest-free pair always matches E and ν.
    pub hydrostatic: HydrostaticStiffness,
    /// The stress reported and compared with the threshold: `Cauchy` (default) or the
    /// seed's `PaperEq3`.
    pub stress: StressMeasure,
    /// Simulation time between release checks, s (`None`: once per frame, as the seed).
    /// A fixed interval makes tearing independent of the frame rate.
    pub release_interval: Option<f32>,
    /// Worker threads for the solver's passes: 0 = all cores, 1 = serial (the sweeps'
    /// team takes at most one thread per core: a member that waits spinning for a core
    /// another member holds would stall every pass).
    pub threads: usize,
    /// How the CPU projects the rest-free coupled pair: `Lanes` (default, eight tets at
    /// once in SIMD lanes) or `Scalar` (the readable reference, one tet at a time).
    pub cpu_kernel: CpuKernel,
    /// The order of a sweep, on the CPU and the GPU alike: `Coloured` (default) or
    /// `Blocks` (fewer synchronisations and dispatches).
    pub cpu_sweep: CpuSweep,
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
            scheme: Scheme::Xpbd,
            frame_dt: 1.0 / 60.0,
            substeps: 10,
            gravity: Vec3::new(0.0, 0.0, -9.81),
            damping: 1.0,
            constraints: ConstraintPair::RestFree,
            projection: TetProjection::Coupled,
            hydrostatic: HydrostaticStiffness::Lambda,
            stress: StressMeasure::Cauchy,
            release_interval: Some(DEFAULT_RELEASE_INTERVAL),
            threads: 0,
            cpu_kernel: CpuKernel::Lanes,
            cpu_sweep: CpuSweep::Coloured,
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

    /// Steps a frame is advanced in: XPBD substeps or implicit Euler steps.
    pub fn steps(&self) -> u32 {
        match self.scheme {
            Scheme::Xpbd => self.substeps,
            Scheme::Newton(p) => p.steps,
        }
    }

    /// Length of one of those steps, s.
    pub fn step_length(&self) -> f32 {
        self.frame_dt / self.steps() as f32
    }

    /// Check ranges; the message names the field.
    pub fn validate(&self) -> Result<(), SolverError> {
        let bad = |field: &'static str, msg: String| Err(SolverError::BadParameter { field, msg });
        if let Scheme::Newton(p) = &self.scheme {
            if let Err((field, msg)) = p.validate() {
                return bad(field, msg);
            }
            if self.constraints != ConstraintPair::RestFree {
                return bad(
                    "scheme",
                    "Newton minimises the rest-free Neo-Hookean energy: it needs constraints: RestFree".into(),
                );
            }
            if self.stress != StressMeasure::Cauchy {
                return bad(
                    "scheme",
                    "Newton has no XPBD multipliers for the seed's eq. 3 stress: it needs stress: Cauchy".into(),
                );
            }
        }
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
        if let Some(dt) = self.release_interval {
            if !(dt.is_finite() && dt > 0.0) {
                return bad(
                    "release_interval",
                    format!("must be a positive time in s, got {dt}"),
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

    /// The Poisson ratios the constraint pair can represent (what a slider may offer).
    pub fn poisson_range(&self) -> (f32, f32) {
        match (self.constraints, self.hydrostatic) {
            (ConstraintPair::GammaShifted, HydrostaticStiffness::Lambda) => (0.13, 0.499),
            _ => (0.0, 0.499),
        }
    }

    /// Check that the constraint pair can represent `material`: the rest-free pair needs
    /// `0 ≤ ν < 0.5` (λ ≥ 0); the γ-shifted pair needs a positive volume stiffness
    /// `λ_H − μ` at small strain (`ν > 1/8` with `hydrostatic: Lambda`) and λ_H > 0.
    pub fn check_material(&self, material: &Material) -> Result<(), SolverError> {
        let nu = material.poisson_ratio;
        let msg = match (self.constraints, self.hydrostatic) {
            (ConstraintPair::RestFree, _) if nu < 0.0 => format!(
                "poisson_ratio {nu} is below 0: the rest-free Neo-Hookean pair needs 0 <= ν < 0.5 (λ >= 0)"
            ),
            (ConstraintPair::GammaShifted, HydrostaticStiffness::Lambda) if nu <= 0.125 => {
                format!(
                    "poisson_ratio {nu} is at or below 1/8: the γ-shifted pair with hydrostatic: Lambda then has no positive bulk stiffness (λ − μ + 2μ/3 <= 0) and the tissue collapses; use ν > 0.125, hydrostatic: LambdaPlusMu or constraints: RestFree"
                )
            }
            (ConstraintPair::GammaShifted, HydrostaticStiffness::LambdaPlusMu) if nu < 0.0 => {
                format!("poisson_ratio {nu} is below 0: the γ-shifted pair needs 0 <= ν < 0.5")
            }
            _ => return Ok(()),
        };
        Err(SolverError::Unrepresentable { msg })
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
    /// The constraint pair cannot represent the material.
    #[error("material: {msg}")]
    Unrepresentable {
        /// What is wrong and what would do.
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
    /// The implicit scheme's coarse level could not be built.
    #[error(transparent)]
    Coarse(#[from] CoarseError),
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
