//! The explicit RK4 stability limit of a body of three-element edges (PHYSICS.md §3).
//!
//! Linearised about a state, the nodes obey `M ẍ + C ẋ + K x = 0` with `C`, `K` built
//! from per-edge damping `c_e` and stiffness `k_e` (each a sum over edges of
//! `c_e (b_e b_eᵀ)`, `b_e = n_e` at one end and `−n_e` at the other). For an eigenpair
//! (λ, u), `m λ² + c λ + k = 0` with `m = u*Mu`, `c = u*Cu`, `k = u*Ku`, so
//! `|λ| ≤ max(c/m, √(k/m))`. The weighted Gershgorin bound
//! `uᵀKu ≤ max_i Σ_{e∋i} k_e (1/m_i + 1/m_j) · uᵀMu` (Cauchy–Schwarz on each edge, exact
//! for one spring between two masses) bounds both ratios by node sums, giving
//! `Ω² = max_i Σ k_e (1/m_i + 1/m_j)` and `δ = max_i Σ c_e (1/m_i + 1/m_j)`; pinned nodes
//! count as infinitely heavy. The Voigt ratios relax at most at `λ_a = k/(c1 + c2_min)`.
//! RK4 is stable for `h|λ| ≤ 2.61` anywhere in the left half-disk, so the step must stay
//! below `2.61 / (max(δ, Ω) + λ_a)`; [`SAFETY`] keeps a margin for the geometric
//! stiffness `|T|/L` of loaded edges, which the rest state does not show.
//!
//! Each edge's damping is the largest it can present: `c1 c2/(c1 + c2)` free (the two
//! dampers in series), `a²c1 + (1 − a)²c2` held at a clamp bound `a` (see `element.rs`),
//! with `c2 = c2_max`.

use super::element::ElementParams;

/// Radius of the largest left half-disk inside the RK4 stability region
/// `|1 + z + z²/2 + z³/6 + z⁴/24| ≤ 1` (2.615, found numerically), rounded down.
pub const RK4_HALF_DISK_RADIUS: f64 = 2.61;

/// Fraction of the limit that automatic substeps use.
pub const SAFETY: f64 = 0.9;

/// The stability limit of a body and what sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StabilityLimit {
    /// Largest stable RK4 step, s (before [`SAFETY`]).
    pub max_step: f64,
    /// Bound Ω on the undamped angular frequencies, rad/s.
    pub frequency_bound: f64,
    /// Bound δ on the damping rates, 1/s.
    pub damping_bound: f64,
    /// Bound λ_a on the Voigt ratios' relaxation rate, 1/s.
    pub ratio_bound: f64,
    /// Node with the largest bound (index into the body's nodes).
    pub worst_node: usize,
}

impl StabilityLimit {
    /// The step automatic substepping aims for, `SAFETY · max_step`, s.
    pub fn safe_step(&self) -> f64 {
        SAFETY * self.max_step
    }
}

impl ElementParams {
    /// The largest damping coefficient this element can present to its nodes, N·s/m.
    pub fn damping_bound(&self) -> f64 {
        let (c1, c2) = (self.voigt_damping, self.damper.max_coefficient());
        let series = if c1 + c2 > 0.0 {
            c1 * c2 / (c1 + c2)
        } else {
            0.0
        };
        let held = |a: f64| a * a * c1 + (1.0 - a) * (1.0 - a) * c2;
        series.max(held(self.ratio_min)).max(held(self.ratio_max))
    }

    /// The fastest relaxation rate of the Voigt ratio, `k/(c1 + c2_min)`, 1/s.
    pub fn ratio_rate_bound(&self) -> f64 {
        if self.ratio_min == self.ratio_max {
            return 0.0;
        }
        self.stiffness / (self.voigt_damping + self.damper.min_coefficient())
    }
}

/// The RK4 stability limit of nodes with `masses` (kg) joined by `edges`, edge `e` having
/// constants `params(e)`; `pinned[i]` nodes do not move.
pub fn stability_limit(
    edges: &[[u32; 2]],
    params: impl Fn(usize) -> ElementParams,
    masses: &[f64],
    pinned: &[bool],
) -> StabilityLimit {
    let inv = |i: u32| {
        if pinned[i as usize] {
            0.0
        } else {
            1.0 / masses[i as usize]
        }
    };
    let mut stiffness_sum = vec![0.0f64; masses.len()];
    let mut damping_sum = vec![0.0f64; masses.len()];
    let mut ratio_bound = 0.0f64;
    for (e, &[i, j]) in edges.iter().enumerate() {
        let p = params(e);
        let w = inv(i) + inv(j);
        let (k, c) = (p.stiffness * w, p.damping_bound() * w);
        for n in [i as usize, j as usize] {
            stiffness_sum[n] += k;
            damping_sum[n] += c;
        }
        ratio_bound = ratio_bound.max(p.ratio_rate_bound());
    }
    let (mut frequency_bound, mut damping_bound) = (0.0f64, 0.0f64);
    let (mut rate, mut worst_node) = (0.0f64, 0usize);
    for n in (0..masses.len()).filter(|&n| !pinned[n]) {
        let (omega, delta) = (stiffness_sum[n].sqrt(), damping_sum[n]);
        frequency_bound = frequency_bound.max(omega);
        damping_bound = damping_bound.max(delta);
        if omega.max(delta) > rate {
            (rate, worst_node) = (omega.max(delta), n);
        }
    }
    let total = rate + ratio_bound;
    StabilityLimit {
        max_step: if total > 0.0 {
            RK4_HALF_DISK_RADIUS / total
        } else {
            f64::INFINITY
        },
        frequency_bound,
        damping_bound,
        ratio_bound,
        worst_node,
    }
}
