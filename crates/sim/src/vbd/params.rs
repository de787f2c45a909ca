//! Settings and errors of the VBD solver.

use glam::Vec3;

use crate::material::MaterialError;

/// The initial guess of each substep's positions (Chen et al. 2024, §3.7 "initialization").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InitialGuess {
    /// `x = xᵗ` (previous positions).
    Previous,
    /// `x = xᵗ + h vᵗ`.
    Inertia,
    /// `x = y = xᵗ + h vᵗ + h² g`.
    InertiaAndGravity,
    /// `x = xᵗ + h vᵗ + h² ã`, `ã = g·clamp((aᵗ·ĝ)/|g|, 0, 1)` with `aᵗ = (vᵗ − vᵗ⁻¹)/h`:
    /// gravity only as far as the node was accelerating along it (the paper's adaptive
    /// guess, which keeps resting nodes from being pushed down every substep).
    #[default]
    Adaptive,
}

/// Settings of [`super::VbdSolver`].
#[derive(Debug, Clone, PartialEq)]
pub struct VbdParams {
    /// Frame length, s.
    pub frame_dt: f32,
    /// Substeps per frame (implicit-Euler steps of length `frame_dt / substeps`).
    pub substeps: u32,
    /// Gauss–Seidel iterations (sweeps over all colours) per substep.
    pub iterations: u32,
    /// Gravity, m/s².
    pub gravity: Vec3,
    /// Velocity damping rate, 1/s: `v ← v·max(0, 1 − damping·h)` each substep (the XPBD
    /// solver's damping, for like-for-like comparisons).
    pub damping: f32,
    /// Rayleigh stiffness damping `k_d`, s (Chen et al. 2024, §3.5): adds
    /// `(k_d/h) ∂²E/∂x_i² (x_i − x_iᵗ)` to the local system. 0 = off.
    pub stiffness_damping: f32,
    /// Chebyshev acceleration with this spectral-radius estimate ρ ∈ (0, 1) (Chen et al.
    /// 2024, §3.8; Wang 2015); `None` = off.
    pub chebyshev_rho: Option<f32>,
    /// Initial guess of each substep.
    pub initial_guess: InitialGuess,
    /// Line-search-free safeguard: a local Newton step longer than this fraction of the
    /// node's shortest incident rest edge is scaled back to it.
    pub max_step_fraction: f32,
    /// Worker threads (1 = on the calling thread).
    pub threads: usize,
}

impl Default for VbdParams {
    fn default() -> Self {
        VbdParams {
            frame_dt: 1.0 / 72.0,
            substeps: 4,
            iterations: 10,
            gravity: Vec3::new(0.0, 0.0, -9.81),
            damping: 1.0,
            stiffness_damping: 0.0,
            chebyshev_rho: None,
            initial_guess: InitialGuess::Adaptive,
            max_step_fraction: 0.5,
            threads: 2,
        }
    }
}

impl VbdParams {
    /// Substep length `h`, s.
    pub fn substep(&self) -> f32 {
        self.frame_dt / self.substeps as f32
    }

    /// Reject settings the solver cannot run.
    pub fn validate(&self) -> Result<(), VbdError> {
        let bad = |what: &'static str, value: String| Err(VbdError::Param { what, value });
        if !(self.frame_dt.is_finite() && self.frame_dt > 0.0) {
            return bad("frame_dt", self.frame_dt.to_string());
        }
        if self.substeps == 0 {
            return bad("substeps", "0".into());
        }
        if self.iterations == 0 {
            return bad("iterations", "0".into());
        }
        if !self.gravity.is_finite() {
            return bad("gravity", format!("{:?}", self.gravity));
        }
        if !(self.damping >= 0.0 && self.damping.is_finite()) {
            return bad("damping", self.damping.to_string());
        }
        if !(self.stiffness_damping >= 0.0 && self.stiffness_damping.is_finite()) {
            return bad("stiffness_damping", self.stiffness_damping.to_string());
        }
        if let Some(rho) = self.chebyshev_rho {
            if !(rho > 0.0 && rho < 1.0) {
                return bad("chebyshev_rho", rho.to_string());
            }
        }
        if !(self.max_step_fraction > 0.0 && self.max_step_fraction.is_finite()) {
            return bad("max_step_fraction", self.max_step_fraction.to_string());
        }
        if self.threads == 0 {
            return bad("threads", "0".into());
        }
        Ok(())
    }
}

/// Why a [`super::VbdSolver`] could not be built or stepped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VbdError {
    /// A setting is out of range.
    #[error("VBD setting {what} = {value} is out of range")]
    Param {
        /// Setting name.
        what: &'static str,
        /// Its value.
        value: String,
    },
    /// The material is invalid.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// The thread pool could not be built.
    #[error("could not start {threads} VBD worker threads: {msg}")]
    ThreadPool {
        /// Requested threads.
        threads: usize,
        /// rayon's message.
        msg: String,
    },
    /// A node's displacement became non-finite.
    #[error("VBD state became non-finite at node {node} in frame {frame}")]
    NonFinite {
        /// First bad node.
        node: usize,
        /// Frame index.
        frame: u64,
    },
}
