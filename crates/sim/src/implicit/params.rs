//! Which time integrator the tet solver uses, and the implicit one's settings.

use serde::{Deserialize, Serialize};

/// How the tet solver advances a frame (`solver.scheme` in a scene).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Scheme {
    /// XPBD small steps (PHYSICS.md §1.2): `substeps` Gauss–Seidel sweeps a frame.
    #[default]
    Xpbd,
    /// Implicit Euler steps solved by Newton's method with a two-level preconditioned
    /// conjugate gradient (docs/physics-notes.md, "The implicit scheme").
    Newton(NewtonParams),
}

impl Scheme {
    /// `"XPBD"` or `"Newton"`, as tables and reports name it.
    pub fn name(&self) -> &'static str {
        match self {
            Scheme::Xpbd => "XPBD",
            Scheme::Newton(_) => "Newton",
        }
    }

    /// The implicit scheme's settings: this scheme's own, or the defaults under XPBD (what
    /// a switch to the implicit scheme starts from).
    pub fn newton_or_default(&self) -> NewtonParams {
        match self {
            Scheme::Newton(p) => *p,
            Scheme::Xpbd => NewtonParams::default(),
        }
    }
}

/// Settings of the implicit scheme.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonParams {
    /// Implicit Euler steps per frame.
    pub steps: u32,
    /// Newton iterations per step.
    pub iterations: u32,
    /// Most conjugate-gradient products per Newton iteration.
    pub cg_iterations: u32,
    /// The conjugate gradient stops when the preconditioned residual falls below this
    /// fraction of its first value (default 0.3: an inexact Newton step, the gradient and
    /// step stops decide how converged the step is; docs/physics-notes.md "The CG
    /// tolerance").
    pub cg_tolerance: f32,
    /// Newton stops early once `|∇G|` has fallen to this fraction of its value at the
    /// step's first iterate (0: always run `iterations`; default 1 %).
    pub gradient_tolerance: f32,
    /// Newton also stops once a step it took moved no node further than this fraction of
    /// the mesh's mean rest edge (0: off; default 1 %, 25 µm on the intestine): a body
    /// already near equilibrium starts from a small gradient, which the relative gradient
    /// stop would reduce a hundredfold by nanometre steps.
    pub step_tolerance: f32,
    /// Edge of the coarse level's cubes, m (`None`: four mean rest edge lengths).
    pub coarse_cell: Option<f32>,
    /// Which stiffness the coarse level's matrix holds and when it is rebuilt (default:
    /// the current tangents every 8 steps, docs/physics-notes.md "The implicit scheme").
    pub coarse_refresh: CoarseRefresh,
    /// The fine level of the preconditioner (default: block Jacobi).
    pub smoother: Smoother,
}

/// The fine level of the implicit scheme's preconditioner (`solver.scheme:
/// Newton((smoother: …))`), added to the coarse correction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Smoother {
    /// Each free node's 3×3 diagonal block of the Hessian, inverted.
    #[default]
    Jacobi,
    /// One symmetric block Gauss–Seidel sweep on the Hessian assembled at the step's first
    /// iterate (positive semi-definite part of each tet's tangent); an iteration whose
    /// first direction meets negative curvature is solved again with `Jacobi`.
    GaussSeidel,
}

/// The stiffness in the coarse level's Galerkin matrix `Pᵀ (M/h² + K) P`
/// (`solver.scheme: Newton((coarse_refresh: …))`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CoarseRefresh {
    /// The small-strain (rest) stiffness, factorised once; a released tet subtracts its
    /// own. It fits less and less as the body rotates and stretches.
    Rest,
    /// The live tets' current tangents, re-assembled and refactorised at the first
    /// iterate of every n-th Newton solve (a step is one solve, or two where the blade's
    /// contact solves it again: docs/physics-notes.md "The coarse refresh"); a released
    /// tet subtracts its blocks at the tangent they were assembled with.
    Steps(u32),
    /// The current tangents, re-assembled at the first iterate of a step after one that
    /// spent more than this many conjugate-gradient products per Newton iteration.
    Products(u32),
}

impl Default for NewtonParams {
    fn default() -> Self {
        NewtonParams {
            steps: 1,
            iterations: 5,
            cg_iterations: 100,
            cg_tolerance: 0.3,
            gradient_tolerance: 0.01,
            step_tolerance: 0.01,
            coarse_cell: None,
            coarse_refresh: CoarseRefresh::Steps(8),
            smoother: Smoother::Jacobi,
        }
    }
}

impl NewtonParams {
    /// The gradient stop for `|∇G| = norm` against the step's first (`first`, set by the
    /// step's first call): the ratio, and whether Newton stops here.
    pub fn gradient_stop(&self, first: &mut Option<f64>, norm: f64) -> (f32, bool) {
        let first = *first.get_or_insert(norm);
        let ratio = if first > 0.0 {
            (norm / first) as f32
        } else {
            0.0
        };
        let stop = norm == 0.0 || norm <= self.gradient_tolerance as f64 * first;
        (ratio, stop)
    }

    /// The step stop: whether a step that moved its furthest node `moved` m is short
    /// enough, on a mesh whose mean rest edge is `mean_edge` m, for Newton to stop after it.
    pub fn step_stop(&self, moved: f32, mean_edge: f32) -> bool {
        moved <= self.step_tolerance * mean_edge
    }

    /// Check ranges: the field (under `solver.scheme`) and what is wrong.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if self.steps == 0 || self.steps > 1000 {
            return Err((
                "scheme.steps",
                format!("must be 1..=1000, got {}", self.steps),
            ));
        }
        if self.iterations == 0 || self.iterations > 100 {
            return Err((
                "scheme.iterations",
                format!("must be 1..=100, got {}", self.iterations),
            ));
        }
        if self.cg_iterations == 0 || self.cg_iterations > 10_000 {
            return Err((
                "scheme.cg_iterations",
                format!("must be 1..=10000, got {}", self.cg_iterations),
            ));
        }
        if !(self.cg_tolerance.is_finite() && self.cg_tolerance > 0.0 && self.cg_tolerance < 1.0) {
            return Err((
                "scheme.cg_tolerance",
                format!("must be in (0, 1), got {}", self.cg_tolerance),
            ));
        }
        if !(self.gradient_tolerance.is_finite() && (0.0..1.0).contains(&self.gradient_tolerance)) {
            return Err((
                "scheme.gradient_tolerance",
                format!("must be in [0, 1), got {}", self.gradient_tolerance),
            ));
        }
        if !(self.step_tolerance.is_finite() && (0.0..1.0).contains(&self.step_tolerance)) {
            return Err((
                "scheme.step_tolerance",
                format!("must be in [0, 1), got {}", self.step_tolerance),
            ));
        }
        if let Some(c) = self.coarse_cell {
            if !(c.is_finite() && c > 0.0) {
                return Err((
                    "scheme.coarse_cell",
                    format!("must be a positive length in m, got {c}"),
                ));
            }
        }
        match self.coarse_refresh {
            CoarseRefresh::Steps(0) | CoarseRefresh::Products(0) => Err((
                "scheme.coarse_refresh",
                "must be Rest, Steps(n) or Products(n) with n ≥ 1, got 0".to_string(),
            )),
            _ => Ok(()),
        }
    }
}
