//! The rest-free Neo-Hookean constraint pair, the default model (docs/physics-notes.md,
//! "Rest-free Neo-Hookean"):
//!
//! ```text
//! C_H = ln J                       compliance 1/(λV)    energy λV/2 (ln J)²
//! C_D = sqrt(I_C − 3 − 2 ln J)     compliance 1/(μV)    energy μV/2 (I_C − 3 − 2 ln J)
//! ```
//!
//! Together they are the classical compressible Neo-Hookean energy
//! `Ψ = μ/2 (I_C − 3) − μ ln J + λ/2 (ln J)²` (Bonet & Wood 2008, eq. 6.28), which
//! linearises to exactly the Lamé pair (μ, λ) of E and ν. Both constraints are zero at
//! rest, so neither carries a multiplier there (the seed's γ-shifted pair carries one of
//! order μVh², whose explicit geometric stiffness bounds the substep, see
//! [`super::stability`]). `I_C − 3 − 2 ln J ≥ 0` for every `F` with `J > 0`, so `C_D` is
//! real; it is evaluated from `H = F − I` ([`Strain`]) so that it is exact near rest.
//! Below `J = J_MIN` the `ln J` term continues along its tangent, so inverted tets still
//! get a finite restoring gradient.

use glam::{Mat3, Vec3};

use super::neo_hookean::{TetProjection, TetTerms, apply_pair, apply_scalar, vertex_gradients};
use super::strain::{Strain, displacement_gradient, log1p_excess};

/// Below this `J`, `ln J` is continued linearly (value and slope match at `J_MIN`).
pub const J_MIN: f32 = 0.1;

/// Below this `C_D` (a strain of ~1e-10) the shape constraint has no usable direction.
pub(super) const MIN_SHAPE: f32 = 1e-10;

/// `L(J) = ln J` (linear continuation below [`J_MIN`]) and `L'(J)`.
#[inline]
pub fn log_volume(s: &Strain) -> (f32, f32) {
    let j = s.j();
    if j > J_MIN {
        (s.j1 - log1p_excess(s.j1), 1.0 / j)
    } else {
        (J_MIN.ln() + (j - J_MIN) / J_MIN, 1.0 / J_MIN)
    }
}

/// `C_H = L(J)` and `∂C_H/∂F = L'(J) cof F`.
// docs/physics-notes.md, rest-free pair, C_H.
#[inline]
pub fn volume_constraint(s: &Strain) -> (f32, Mat3) {
    let (l, dl) = log_volume(s);
    (l, s.cof_f() * dl)
}

/// `ψ̂ = I_C − 3 − 2 L(J) ≥ 0` and `½ ∂ψ̂/∂F = F − L'(J) cof F`.
// docs/physics-notes.md, rest-free pair, C_D² = ψ̂.
#[inline]
pub fn shape_energy(s: &Strain) -> (f32, Mat3) {
    let j = s.j();
    let (psi, half_grad) = if j > J_MIN {
        // I_C − 3 = 2 tr H + ‖H‖²,  −2 ln J = −2 (tr H + I₂ + det H) + 2 (x − ln(1+x)).
        let psi = s.h_norm2() - 2.0 * s.i2 - 2.0 * s.det_h + 2.0 * log1p_excess(s.j1);
        (psi, s.j_f_minus_cof() * (1.0 / j))
    } else {
        let (l, dl) = log_volume(s);
        let f = Mat3::IDENTITY + s.h;
        (2.0 * s.tr + s.h_norm2() - 2.0 * l, f - s.cof_f() * dl)
    };
    (psi.max(0.0), half_grad)
}

/// `C_D = sqrt(ψ̂)` and `∂C_D/∂F = (F − L' cof F)/C_D`; `None` at rest (no direction).
// docs/physics-notes.md, rest-free pair, C_D.
#[inline]
pub fn shape_constraint(s: &Strain) -> Option<(f32, Mat3)> {
    let (psi, half_grad) = shape_energy(s);
    let c = psi.sqrt();
    (c >= MIN_SHAPE).then(|| (c, half_grad * (1.0 / c)))
}

/// Project both rest-free constraints of one tet in place (`x` holds displacements);
/// returns the volume multiplier of this substep.
#[inline]
pub fn project_rest_free(
    x: &mut [Vec3; 4],
    w: &[f32; 4],
    t: &TetTerms,
    mode: TetProjection,
) -> f32 {
    match mode {
        TetProjection::Coupled => project_coupled(x, w, t),
        TetProjection::Sequential => project_sequential(x, w, t),
    }
}

/// The 2×2 block XPBD step of both constraints ([`apply_pair`]); one scalar step where only
/// one applies (at rest: `C_D` has no direction; ν = 0: λ = 0, no volume constraint).
// PHYSICS.md §1.2, XPBD update (block form, λ = 0 at the start of the substep).
fn project_coupled(x: &mut [Vec3; 4], w: &[f32; 4], t: &TetTerms) -> f32 {
    let s = Strain::of(displacement_gradient(x, &t.dm_inv));
    let shape = shape_constraint(&s);
    let with_volume = t.alpha_h.is_finite();
    let (c_h, dch) = volume_constraint(&s);
    let g_h = vertex_gradients(dch, &t.dm_inv);
    let Some((c_d, dcd)) = shape else {
        return if with_volume {
            apply_scalar(x, w, &g_h, c_h, t.alpha_h)
        } else {
            0.0
        };
    };
    let g_d = vertex_gradients(dcd, &t.dm_inv);
    if !with_volume {
        apply_scalar(x, w, &g_d, c_d, t.alpha_d);
        return 0.0;
    }
    apply_pair(x, w, (&g_h, c_h, t.alpha_h), (&g_d, c_d, t.alpha_d))
}

/// Volume, then shape, each a scalar XPBD step.
fn project_sequential(x: &mut [Vec3; 4], w: &[f32; 4], t: &TetTerms) -> f32 {
    let mut dl_h = 0.0;
    if t.alpha_h.is_finite() {
        let s = Strain::of(displacement_gradient(x, &t.dm_inv));
        let (c_h, dch) = volume_constraint(&s);
        dl_h = apply_scalar(x, w, &vertex_gradients(dch, &t.dm_inv), c_h, t.alpha_h);
    }
    let s = Strain::of(displacement_gradient(x, &t.dm_inv));
    if let Some((c_d, dcd)) = shape_constraint(&s) {
        apply_scalar(x, w, &vertex_gradients(dcd, &t.dm_inv), c_d, t.alpha_d);
    }
    dl_h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strain(f: Mat3) -> Strain {
        Strain::of(f - Mat3::IDENTITY)
    }

    /// ψ̂ and its gradient against f64 finite differences of `I_C − 3 − 2 ln J`.
    #[test]
    fn shape_gradient_matches_finite_differences() {
        let f = Mat3::from_cols_array(&[1.1, 0.2, -0.1, 0.05, 0.9, 0.3, 0.0, -0.2, 1.2]);
        let psi64 = |f: [[f64; 3]; 3]| {
            let ic: f64 = f.iter().flatten().map(|v| v * v).sum();
            let j = f[0][0] * (f[1][1] * f[2][2] - f[2][1] * f[1][2])
                - f[1][0] * (f[0][1] * f[2][2] - f[2][1] * f[0][2])
                + f[2][0] * (f[0][1] * f[1][2] - f[1][1] * f[0][2]);
            ic - 3.0 - 2.0 * j.ln()
        };
        let cols = f.to_cols_array_2d().map(|c| c.map(|v| v as f64));
        let (psi, half) = shape_energy(&strain(f));
        assert!((psi as f64 - psi64(cols)).abs() < 1e-5);
        let eps = 1e-6;
        for c in 0..3 {
            for r in 0..3 {
                let (mut p, mut m) = (cols, cols);
                p[c][r] += eps;
                m[c][r] -= eps;
                let fd = (psi64(p) - psi64(m)) / (2.0 * eps);
                let got = 2.0 * half.col(c)[r] as f64;
                assert!((fd - got).abs() < 1e-4, "({r},{c}) {fd} vs {got}");
            }
        }
    }

    #[test]
    fn both_constraints_vanish_at_rest() {
        let s = strain(Mat3::IDENTITY);
        assert_eq!(volume_constraint(&s).0, 0.0);
        assert!(shape_constraint(&s).is_none());
        let mut u = [Vec3::ZERO; 4];
        let t = TetTerms {
            dm_inv: Mat3::IDENTITY,
            alpha_h: 0.5,
            alpha_d: 0.5,
            gamma: 1.0,
        };
        for mode in [TetProjection::Coupled, TetProjection::Sequential] {
            project_rest_free(&mut u, &[1.0; 4], &t, mode);
            assert_eq!(u, [Vec3::ZERO; 4]);
        }
    }

    /// ψ̂ ≥ 0 for pure dilation and compression, and stays finite through inversion.
    #[test]
    fn shape_energy_is_non_negative_and_finite() {
        for s in [0.3f32, 0.9, 0.999, 1.001, 1.5, 3.0] {
            let (psi, _) = shape_energy(&strain(Mat3::from_diagonal(Vec3::splat(s))));
            assert!(psi >= 0.0, "s = {s}: {psi}");
        }
        for j in [0.05f32, 0.0, -0.5] {
            let f = Mat3::from_diagonal(Vec3::new(j, 1.0, 1.0));
            let (psi, g) = shape_energy(&strain(f));
            assert!(
                psi > 0.0 && psi.is_finite() && g.is_finite(),
                "J = {j}: {psi}"
            );
            let (c, dc) = volume_constraint(&strain(f));
            assert!(c.is_finite() && dc.is_finite());
        }
    }

    /// A stretched tet relaxes toward rest under the stiff pair (volume and shape).
    #[test]
    fn stiff_projection_restores_a_stretched_tet() {
        let mut x = [Vec3::ZERO, Vec3::X * 0.2, Vec3::ZERO, Vec3::Z * -0.1];
        let t = TetTerms {
            dm_inv: Mat3::IDENTITY,
            alpha_h: 1e-6,
            alpha_d: 1e-6,
            gamma: 1.0,
        };
        for _ in 0..200 {
            project_rest_free(&mut x, &[1.0; 4], &t, TetProjection::Coupled);
        }
        let s = Strain::of(displacement_gradient(&x, &Mat3::IDENTITY));
        assert!(s.j1.abs() < 1e-3, "J − 1 = {}", s.j1);
        assert!(shape_energy(&s).0 < 1e-5, "ψ̂ = {}", shape_energy(&s).0);
    }
}
