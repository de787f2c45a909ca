//! The rest-free pair's coupled projection for eight tets at once (one per SIMD lane):
//! the same formulas, in the same order, as the scalar reference
//! ([`super::rest_free`], [`super::strain`], [`super::neo_hookean::apply_pair`]), with each
//! branch of the reference evaluated where a lane of the block takes it and chosen by a
//! mask ([`Taken`]). Tets of one colour share no node, so eight of them are independent
//! (PHYSICS.md §1.2, parallel form).

use super::lanes::{LaneMath, M3, V3};
use super::rest_free::{J_MIN, MIN_SHAPE};
use super::strain::SERIES_LIMIT;

/// Eight tets' inputs (padding lanes: zero displacement and weight, `Dm⁻¹ = I`, unit
/// compliances, not live).
#[derive(Debug, Clone, Copy)]
pub struct TetLanes<L> {
    /// The four nodes' displacements from rest; projected in place.
    pub u: [V3<L>; 4],
    /// The four nodes' inverse masses.
    pub w: [L; 4],
    /// Inverse rest shape matrices `Dm⁻¹`.
    pub dm_inv: M3<L>,
    /// `α̃_H = 1/(λ V h²)` (infinite at λ = 0: no volume constraint).
    pub alpha_h: L,
    /// `α̃_D = 1/(μ V h²)`.
    pub alpha_d: L,
    /// All bits set in the lanes that hold a live tet.
    pub live: L,
}

/// `x − ln(1 + x)`: the series below [`SERIES_LIMIT`], else direct (strain.rs
/// `log1p_excess`).
#[inline(always)]
pub(crate) fn log1p_excess<L: LaneMath>(x: L) -> L {
    log1p_excess_in(x, false)
}

/// [`log1p_excess`], by the series alone where `all_series` says every lane takes it.
#[inline(always)]
fn log1p_excess_in<L: LaneMath>(x: L, all_series: bool) -> L {
    let series = x.abs().simd_lt(L::splat(SERIES_LIMIT));
    match Taken::given(all_series, series) {
        Taken::All => log1p_excess_series(x),
        Taken::None => log1p_excess_direct(x),
        Taken::Some => series.select(log1p_excess_series(x), log1p_excess_direct(x)),
    }
}

/// `x − ln(1 + x)` by its series.
#[inline(always)]
fn log1p_excess_series<L: LaneMath>(x: L) -> L {
    let s = L::splat;
    let x2 = x * x;
    let tail = s(-1.0 / 7.0) + x * s(0.125);
    let tail = s(-0.2) + x * (s(1.0 / 6.0) + x * tail);
    x2 * (s(0.5) + x * (s(-1.0 / 3.0) + x * (s(0.25) + x * tail)))
}

/// `x − ln(1 + x)` directly.
#[inline(always)]
fn log1p_excess_direct<L: LaneMath>(x: L) -> L {
    x - (L::ONE + x).ln()
}

/// Which lanes a mask sets: a branch of the reference that no lane takes is not evaluated
/// (each lane's value is the same either way: `select` only picks).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Taken {
    /// Every lane.
    All,
    /// No lane.
    None,
    /// Some lanes.
    Some,
}

impl Taken {
    /// The lanes `mask` sets.
    #[inline(always)]
    pub(crate) fn of<L: LaneMath>(mask: L) -> Taken {
        match mask.bits() {
            0 => Taken::None,
            b if b == L::ALL => Taken::All,
            _ => Taken::Some,
        }
    }

    /// [`Taken::All`] where the caller knows every lane sets `mask` (the common block:
    /// the mask is then not looked at), else the lanes `mask` sets.
    #[inline(always)]
    pub(crate) fn given<L: LaneMath>(known_all: bool, mask: L) -> Taken {
        if known_all {
            Taken::All
        } else {
            Taken::of(mask)
        }
    }
}

/// The invariants of `F = I + H` from `H` (strain.rs `Strain`).
pub(crate) struct StrainLanes<L> {
    /// `H`.
    pub(crate) h: M3<L>,
    /// `tr H`.
    pub(crate) tr: L,
    /// `I₂(H)`.
    pub(crate) i2: L,
    /// `det H`.
    pub(crate) det_h: L,
    /// `J − 1`.
    pub(crate) j1: L,
    /// `J`.
    pub(crate) j: L,
    /// `cof H`.
    pub(crate) cof_h: M3<L>,
}

impl<L: LaneMath> StrainLanes<L> {
    /// The invariants of `I + h`.
    #[inline(always)]
    pub(crate) fn of(h: M3<L>) -> Self {
        let tr = h.trace();
        let tr_h2 = h.mul_mat(&h).trace();
        let i2 = L::splat(0.5) * (tr * tr - tr_h2);
        let det_h = h.determinant();
        let j1 = tr + i2 + det_h;
        StrainLanes {
            h,
            tr,
            i2,
            det_h,
            j1,
            j: L::ONE + j1,
            cof_h: h.cofactor(),
        }
    }

    /// `cof F = (1 + tr H) I − Hᵀ + cof H`.
    #[inline(always)]
    pub(crate) fn cof_f(&self) -> M3<L> {
        M3::diagonal(L::ONE + self.tr) - self.h.transpose() + self.cof_h
    }

    /// `J F − cof F = (I₂ + det H) I + H + Hᵀ + (J − 1) H − cof H`.
    #[inline(always)]
    fn j_f_minus_cof(&self) -> M3<L> {
        M3::diagonal(self.i2 + self.det_h) + self.h + self.h.transpose() + self.h * self.j1
            - self.cof_h
    }
}

/// `L(J)`, `L'(J)` and whether `J > J_MIN` (rest_free.rs `log_volume`), given
/// `excess = log1p_excess(J − 1)`.
// docs/physics-notes.md, rest-free pair, C_H.
#[inline(always)]
pub(crate) fn log_volume<L: LaneMath>(s: &StrainLanes<L>, excess: L) -> (L, L, L) {
    log_volume_in(s, excess, false)
}

/// [`log_volume`], above `J_MIN` alone where `all_above` says every lane is.
#[inline(always)]
fn log_volume_in<L: LaneMath>(s: &StrainLanes<L>, excess: L, all_above: bool) -> (L, L, L) {
    let j = s.j;
    let above = j.simd_gt(L::splat(J_MIN));
    // Plain functions, not closures: each arm is compiled into the caller (and its AVX).
    let (l, dl) = match Taken::given(all_above, above) {
        Taken::All => (s.j1 - excess, L::ONE / j),
        Taken::None => (log_volume_below(j), L::splat(1.0 / J_MIN)),
        Taken::Some => (
            above.select(s.j1 - excess, log_volume_below(j)),
            above.select(L::ONE / j, L::splat(1.0 / J_MIN)),
        ),
    };
    (l, dl, above)
}

/// `L(J)` below `J_MIN`: continued linearly.
#[inline(always)]
fn log_volume_below<L: LaneMath>(j: L) -> L {
    L::splat(J_MIN.ln()) + (j - L::splat(J_MIN)) / L::splat(J_MIN)
}

/// `ψ̂ ≥ 0` and `½ ∂ψ̂/∂F = F − L' cof F` (rest_free.rs `shape_energy`), given
/// `log_volume` and the excess.
// docs/physics-notes.md, rest-free pair, C_D² = ψ̂.
#[inline(always)]
pub(crate) fn shape_energy<L: LaneMath>(
    s: &StrainLanes<L>,
    volume: (L, L, L),
    excess: L,
    cof_f: &M3<L>,
) -> (L, M3<L>) {
    shape_energy_in(s, volume, excess, cof_f, false)
}

/// [`shape_energy`], above `J_MIN` alone where `all_above` says every lane is.
#[inline(always)]
fn shape_energy_in<L: LaneMath>(
    s: &StrainLanes<L>,
    volume: (L, L, L),
    excess: L,
    cof_f: &M3<L>,
    all_above: bool,
) -> (L, M3<L>) {
    let (l, dl, above) = volume;
    let h_norm2 = s.h.norm2();
    let (psi, grad) = match Taken::given(all_above, above) {
        Taken::All => shape_energy_above(s, h_norm2, excess),
        Taken::None => shape_energy_below(s, h_norm2, l, dl, cof_f),
        Taken::Some => {
            let (psi_a, grad_a) = shape_energy_above(s, h_norm2, excess);
            let (psi_b, grad_b) = shape_energy_below(s, h_norm2, l, dl, cof_f);
            (
                above.select(psi_a, psi_b),
                select_m3(above, &grad_a, &grad_b),
            )
        }
    };
    (psi.max(L::ZERO), grad)
}

/// `ψ̂` (before its clamp at 0) and `½ ∂ψ̂/∂F` above `J_MIN`.
#[inline(always)]
fn shape_energy_above<L: LaneMath>(s: &StrainLanes<L>, h_norm2: L, excess: L) -> (L, M3<L>) {
    let two = L::splat(2.0);
    let j = s.j;
    let psi = h_norm2 - two * s.i2 - two * s.det_h + two * excess;
    (psi, s.j_f_minus_cof() * (L::ONE / j))
}

/// `ψ̂` (before its clamp at 0) and `½ ∂ψ̂/∂F` below `J_MIN`.
#[inline(always)]
fn shape_energy_below<L: LaneMath>(
    s: &StrainLanes<L>,
    h_norm2: L,
    l: L,
    dl: L,
    cof_f: &M3<L>,
) -> (L, M3<L>) {
    let two = L::splat(2.0);
    let psi = two * s.tr + h_norm2 - two * l;
    (psi, M3::diagonal(L::ONE) + s.h - *cof_f * dl)
}

/// `C_D = sqrt(ψ̂)`, `∂C_D/∂F`, and the lanes where `C_D` has a direction
/// (rest_free.rs `shape_constraint`), given `log_volume` and the excess.
// docs/physics-notes.md, rest-free pair, C_D.
#[inline(always)]
fn shape_constraint<L: LaneMath>(
    s: &StrainLanes<L>,
    volume: (L, L, L),
    excess: L,
    cof_f: &M3<L>,
    common: bool,
) -> (L, M3<L>, L) {
    let (psi, half) = shape_energy_in(s, volume, excess, cof_f, common);
    let c = psi.sqrt();
    let has = c.simd_ge(L::splat(MIN_SHAPE));
    (c, half * (L::ONE / c), has)
}

/// `a` in the lanes where `m` is set, else `b`.
#[inline(always)]
pub(crate) fn select_v3<L: LaneMath>(m: L, a: V3<L>, b: V3<L>) -> V3<L> {
    V3 {
        x: m.select(a.x, b.x),
        y: m.select(a.y, b.y),
        z: m.select(a.z, b.z),
    }
}

/// `a` in the lanes where `m` is set, else `b`.
#[inline(always)]
pub(crate) fn select_m3<L: LaneMath>(m: L, a: &M3<L>, b: &M3<L>) -> M3<L> {
    M3 {
        c0: select_v3(m, a.c0, b.c0),
        c1: select_v3(m, a.c1, b.c1),
        c2: select_v3(m, a.c2, b.c2),
    }
}

/// `G = (∂C/∂F) Dm⁻ᵀ`: `∇x1..3` = columns of G, `∇x0 = −(∇x1+∇x2+∇x3)`.
// PHYSICS.md §1.2, vertex gradients.
#[inline(always)]
fn vertex_gradients<L: LaneMath>(dcdf: &M3<L>, dm_inv_t: &M3<L>) -> [V3<L>; 4] {
    let g = dcdf.mul_mat(dm_inv_t);
    [-(g.c0 + g.c1 + g.c2), g.c0, g.c1, g.c2]
}

#[inline(always)]
fn weighted_dot<L: LaneMath>(w: &[L; 4], a: &[V3<L>; 4], b: &[V3<L>; 4]) -> L {
    w[0] * a[0].dot(b[0]) + w[1] * a[1].dot(b[1]) + w[2] * a[2].dot(b[2]) + w[3] * a[3].dot(b[3])
}

/// One row of the 2×2 system, or an empty row (zero gradient and value, unit compliance)
/// where its constraint does not apply (`on` clear); `all_on`: the caller knows it applies
/// in every lane.
#[inline(always)]
fn row<L: LaneMath>(all_on: bool, on: L, g: [V3<L>; 4], c: L, alpha: L) -> ([V3<L>; 4], L, L) {
    if Taken::given(all_on, on) == Taken::All {
        return (g, c, alpha);
    }
    (
        // Written out, not `map` (see lane_pass.rs).
        [
            select_v3(on, g[0], V3::ZERO),
            select_v3(on, g[1], V3::ZERO),
            select_v3(on, g[2], V3::ZERO),
            select_v3(on, g[3], V3::ZERO),
        ],
        on.select(c, L::ZERO),
        on.select(alpha, L::ONE),
    )
}

/// Project the eight tets' rest-free pair in place; returns each lane's volume multiplier
/// of this substep (0 where there is no volume constraint or no live tet).
// PHYSICS.md §1.2, XPBD update (block form, λ = 0 at the start of the substep);
// docs/physics-notes.md, rest-free pair.
#[inline(always)]
pub fn project_rest_free_lanes<L: LaneMath>(t: &mut TetLanes<L>) -> L {
    let du = M3 {
        c0: t.u[1] - t.u[0],
        c1: t.u[2] - t.u[0],
        c2: t.u[3] - t.u[0],
    };
    let s = StrainLanes::of(du.mul_mat(&t.dm_inv));
    // The common block: every lane small-strained (the series, so above J_MIN) with a
    // volume constraint. Its projection is one straight run of code without the three
    // branches' joins, which the compiler schedules with fewer values on the stack
    // (`scripts/lane-instructions.sh`: 180 → 171 instructions a tet). Each lane's
    // operations are the same either way.
    let series = s.j1.abs().simd_lt(L::splat(SERIES_LIMIT));
    let above = s.j.simd_gt(L::splat(J_MIN));
    if Taken::of(series & above & t.alpha_h.is_finite()) == Taken::All {
        project_strained(t, &s, true)
    } else {
        project_strained(t, &s, false)
    }
}

/// The rest of [`project_rest_free_lanes`] once the strain is known; `common`: every lane
/// takes the series, is above `J_MIN` and has a volume constraint (checked by the caller).
#[inline(always)]
fn project_strained<L: LaneMath>(t: &mut TetLanes<L>, s: &StrainLanes<L>, common: bool) -> L {
    let dm_inv_t = t.dm_inv.transpose();
    let excess = log1p_excess_in(s.j1, common);
    let volume = log_volume_in(s, excess, common);
    let (c_h, dl, _) = volume;
    let cof_f = s.cof_f();
    let (g_h, c_h, alpha_h) = row(
        common,
        t.alpha_h.is_finite(),
        vertex_gradients(&(cof_f * dl), &dm_inv_t),
        c_h,
        t.alpha_h,
    );
    let (c_d, dcd, has_shape) = shape_constraint(s, volume, excess, &cof_f, common);
    let (g_d, c_d, alpha_d) = row(
        false,
        has_shape,
        vertex_gradients(&dcd, &dm_inv_t),
        c_d,
        t.alpha_d,
    );
    // apply_pair: scale to O(1), solve, skip lanes with a singular (or NaN) system.
    let a = weighted_dot(&t.w, &g_h, &g_h) + alpha_h;
    let b = weighted_dot(&t.w, &g_h, &g_d);
    let d = weighted_dot(&t.w, &g_d, &g_d) + alpha_d;
    let sc = L::ONE / (a + d);
    let (a, b, d) = (a * sc, b * sc, d * sc);
    let det = a * d - b * b;
    let ok = det.simd_gt(L::ZERO) & t.live;
    let (r1, r2) = (-c_h * sc, -c_d * sc);
    let dl_h = ok.select((r1 * d - b * r2) / det, L::ZERO);
    let dl_d = ok.select((a * r2 - b * r1) / det, L::ZERO);
    let all_ok = Taken::of(ok) == Taken::All;
    for i in 0..4 {
        let dx = (g_h[i] * dl_h + g_d[i] * dl_d) * t.w[i];
        t.u[i] = t.u[i]
            + if all_ok {
                dx
            } else {
                select_v3(ok, dx, V3::ZERO)
            };
    }
    dl_h
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, Vec3};

    use super::*;
    use crate::xpbd::lanes::{LANES, Lane};
    use crate::xpbd::neo_hookean::{TetProjection, TetTerms};
    use crate::xpbd::rest_free::project_rest_free;

    /// A tet's displacements: 0 at rest, growing with `k`, and a nearly flattened one
    /// (J < J_MIN) and an inverted one.
    fn displacements(k: usize) -> [Vec3; 4] {
        let a = k as f32 * 0.07;
        let base = [
            Vec3::ZERO,
            Vec3::new(0.3 * a, -0.1 * a, 0.05 * a),
            Vec3::new(-0.02 * a, 0.2 * a, 0.1 * a),
            Vec3::new(0.04 * a, -0.03 * a, -0.25 * a),
        ];
        match k {
            6 => [
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, -0.95),
            ],
            7 => [
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::new(0.1, 0.0, -1.4),
            ],
            _ => base,
        }
    }

    fn terms(k: usize, alpha_h: f32) -> TetTerms {
        TetTerms {
            dm_inv: Mat3::from_diagonal(Vec3::new(1.0, 1.1, 0.9 + 0.01 * k as f32)),
            alpha_h,
            alpha_d: 0.3 + 0.05 * k as f32,
            gamma: 1.0,
        }
    }

    /// Lane k projects what the scalar reference projects for tet k, in every branch
    /// (rest, small and large strain, J below J_MIN, inverted, no volume constraint),
    /// and a lane that is not live stays put: with the portable lanes, and with the AVX
    /// ones where the CPU has AVX2. Once with the eight cases side by side (every mask
    /// mixed: both sides of each branch evaluated and selected), then with each case in
    /// all eight lanes (a branch no lane takes is skipped, `Taken`; the small strains with
    /// a volume constraint take the common block's straight path). Broken on purpose
    /// once each: `row`'s every-lane arm given a unit compliance, `log_volume`'s arms
    /// given the other side's `L'`, the common block's volume row a unit compliance: fails.
    #[test]
    fn lanes_match_the_scalar_reference() {
        let mixed = |k: usize| (k, k != 5);
        check::<wide::f32x8>(mixed);
        for case in 0..LANES {
            check::<wide::f32x8>(|_| (case, true));
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            use crate::xpbd::lane_avx::Avx;
            check::<Avx>(mixed);
            for case in 0..LANES {
                check::<Avx>(|_| (case, true));
            }
        }
    }

    /// `lane(k)`: which of the [`displacements`] lane k holds and whether it is live.
    fn check<L: Lane>(lane: impl Fn(usize) -> (usize, bool)) {
        for alpha_h in [0.2f32, f32::INFINITY] {
            let case = |k: usize| lane(k).0;
            let w = |k: usize| [1.0, 0.5 + 0.1 * k as f32, 2.0, 0.0];
            let u: [[Vec3; 4]; LANES] = std::array::from_fn(|k| displacements(case(k)));
            let dm: [Mat3; LANES] = std::array::from_fn(|k| terms(case(k), alpha_h).dm_inv);
            let live: [f32; LANES] = std::array::from_fn(|k| {
                if lane(k).1 {
                    f32::from_bits(u32::MAX)
                } else {
                    0.0
                }
            });
            let mut lanes = TetLanes {
                u: std::array::from_fn(|j| V3::gather(&u.map(|t| t[j]))),
                w: std::array::from_fn(|j| L::new(std::array::from_fn(|k| w(k)[j]))),
                dm_inv: M3::gather(&dm),
                alpha_h: L::splat(alpha_h),
                alpha_d: L::new(std::array::from_fn(|k| terms(case(k), alpha_h).alpha_d)),
                live: L::new(live),
            };
            let dl = project_rest_free_lanes(&mut lanes).to_array();
            for k in 0..LANES {
                let mut x = u[k];
                let terms = terms(case(k), alpha_h);
                let want = if lane(k).1 {
                    project_rest_free(&mut x, &w(k), &terms, TetProjection::Coupled)
                } else {
                    0.0
                };
                let tol = 2e-6 * (1.0 + want.abs());
                assert!(
                    (dl[k] - want).abs() <= tol,
                    "lane {k}: Δλ {} vs {want}",
                    dl[k]
                );
                for (j, want) in x.iter().enumerate() {
                    let got = lanes.u[j].lane(k);
                    assert!(
                        got.abs_diff_eq(*want, 2e-6),
                        "lane {k} node {j} (α_H {alpha_h}): {got} vs {want}"
                    );
                }
            }
        }
    }
}
