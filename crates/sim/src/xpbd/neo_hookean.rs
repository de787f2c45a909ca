//! Projection of the Neo-Hookean tet constraints (PHYSICS.md §1.2, Macklin & Müller 2021).
//!
//! Two constraint pairs ([`ConstraintPair`], chosen per tet by
//! [`super::tet_constraint`]): the rest-free pair (default, [`super::rest_free`]) and the
//! seed paper's γ-shifted pair, written here:
//! `C_D = ‖F‖_F` with compliance `1/(μV)` and `C_H = det F − γ`, `γ = 1 + μ/λ`, with
//! compliance `1/(λV)`. The CPU reference solves both constraints of a tet together (a 2×2
//! system, as Macklin & Müller 2021 §5 recommend): because `∇C_H ∥ ∇C_D` at rest, the
//! coupled solve leaves the rest state exactly stationary, while projecting H then D one
//! after the other leaves a residual of order `h²·S/α` per substep. The sequential form is
//! kept as an option for comparison.

use glam::{Mat3, Vec3};

use crate::mesh::shape_matrix;

/// Which pair of Neo-Hookean constraints a tet carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum ConstraintPair {
    /// `C_H = ln J`, `C_D = sqrt(I_C − 3 − 2 ln J)`: zero energy, force and multiplier at
    /// rest for every ν in [0, 0.5) (default; docs/physics-notes.md).
    #[default]
    RestFree,
    /// `C_H = det F − γ`, `C_D = ‖F‖_F` as the seed paper and PHYSICS.md §1.2 write it:
    /// both carry a multiplier at rest, which bounds the substep (stiffness number ≤ 1).
    GammaShifted,
}

/// How the two constraints of one tet are projected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum TetProjection {
    /// Both constraints in one 2×2 solve (default; exact rest state).
    #[default]
    Coupled,
    /// Hydrostatic, then deviatoric, each a scalar XPBD update (PHYSICS.md §1.2 as written).
    Sequential,
}

/// Inputs of one tet projection that do not change within a substep.
#[derive(Debug, Clone, Copy)]
pub struct TetTerms {
    /// Inverse rest shape matrix `Dm⁻¹`.
    pub dm_inv: Mat3,
    /// `α̃_H = 1/(λ V h²)`.
    pub alpha_h: f32,
    /// `α̃_D = 1/(μ V h²)`.
    pub alpha_d: f32,
    /// Rest-state shift `γ = 1 + μ/λ`.
    pub gamma: f32,
}

#[cfg(test)]
impl TetTerms {
    /// Terms of a rest tet with `Dm = I` and one compliance `alpha` for both constraints
    /// (tests).
    pub(super) fn uniform(alpha: f32, gamma: f32) -> TetTerms {
        TetTerms {
            dm_inv: Mat3::IDENTITY,
            alpha_h: alpha,
            alpha_d: alpha,
            gamma,
        }
    }
}

/// Deformation gradient `F = Ds Dm⁻¹`.
// PHYSICS.md §1.2, F = Ds Dm^-1.
#[inline]
pub fn deformation_gradient(x: &[Vec3; 4], dm_inv: &Mat3) -> Mat3 {
    shape_matrix(x[0], x[1], x[2], x[3]) * *dm_inv
}

/// Deformation gradient from node displacements `u = x − X`:
/// `F = Ds Dm⁻¹ = (Dm + Du) Dm⁻¹ = I + Du Dm⁻¹`, exact in f32 for small `u` wherever the
/// body sits (no subtraction of large coordinates).
// PHYSICS.md §1.2, F = Ds Dm^-1.
#[inline]
pub fn deformation_gradient_from_displacement(u: &[Vec3; 4], dm_inv: &Mat3) -> Mat3 {
    Mat3::IDENTITY + shape_matrix(u[0], u[1], u[2], u[3]) * *dm_inv
}

/// `∂det(F)/∂F = [f2×f3, f3×f1, f1×f2]` (columns).
// PHYSICS.md §1.2, table row C_H.
#[inline]
pub fn det_gradient(f: &Mat3) -> Mat3 {
    Mat3::from_cols(
        f.y_axis.cross(f.z_axis),
        f.z_axis.cross(f.x_axis),
        f.x_axis.cross(f.y_axis),
    )
}

/// Vertex gradients from `∂C/∂F`: `G = (∂C/∂F) Dm⁻ᵀ`, `∇x1..3` = columns of G,
/// `∇x0 = −(∇x1+∇x2+∇x3)`.
// PHYSICS.md §1.2, vertex gradients.
#[inline]
pub(super) fn vertex_gradients(dcdf: Mat3, dm_inv: &Mat3) -> [Vec3; 4] {
    let g = dcdf * dm_inv.transpose();
    [
        -(g.x_axis + g.y_axis + g.z_axis),
        g.x_axis,
        g.y_axis,
        g.z_axis,
    ]
}

#[inline]
pub(super) fn weighted_dot(w: &[f32; 4], a: &[Vec3; 4], b: &[Vec3; 4]) -> f32 {
    w[0] * a[0].dot(b[0]) + w[1] * a[1].dot(b[1]) + w[2] * a[2].dot(b[2]) + w[3] * a[3].dot(b[3])
}

/// Coupled 2×2 XPBD step for (C_H, C_D) with λ reset each substep:
/// `[S_HH+α̃_H, S_HD; S_HD, S_DD+α̃_D] Δλ = −C`, `x_i += w_i (∇_i C_H Δλ_H + ∇_i C_D Δλ_D)`.
// PHYSICS.md §1.2, XPBD update (block form of Δλ = (−C − α̃λ)/(Σ w|∇C|² + α̃) with λ = 0).
pub(super) fn project_coupled(x: &mut [Vec3; 4], w: &[f32; 4], t: &TetTerms) -> f32 {
    let f = deformation_gradient_from_displacement(x, &t.dm_inv);
    let c_h = f.determinant() - t.gamma;
    let g_h = vertex_gradients(det_gradient(&f), &t.dm_inv);
    let norm =
        (f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared()).sqrt();
    if norm < 1e-12 {
        // Collapsed to a point: only the volume term has a gradient.
        return apply_scalar(x, w, &g_h, c_h, t.alpha_h);
    }
    let c_d = norm;
    let g_d = vertex_gradients(f * (1.0 / norm), &t.dm_inv);
    apply_pair(x, w, (&g_h, c_h, t.alpha_h), (&g_d, c_d, t.alpha_d))
}

/// One constraint of a pair: vertex gradients, value `C`, compliance `α̃`.
pub(super) type PairTerm<'a> = (&'a [Vec3; 4], f32, f32);

/// The 2×2 block XPBD update of two constraints (volume `h`, shape `d`), λ reset each
/// substep: `[S_HH+α̃_H, S_HD; S_HD, S_DD+α̃_D] Δλ = −C`, `x_i += w_i (∇_i C_H Δλ_H +
/// ∇_i C_D Δλ_D)`; returns `Δλ_H`.
// PHYSICS.md §1.2, XPBD update (block form of Δλ = (−C − α̃λ)/(Σ w|∇C|² + α̃) with λ = 0).
pub(super) fn apply_pair(x: &mut [Vec3; 4], w: &[f32; 4], h: PairTerm<'_>, d: PairTerm<'_>) -> f32 {
    let ((g_h, c_h, alpha_h), (g_d, c_d, alpha_d)) = (h, d);
    let a = weighted_dot(w, g_h, g_h) + alpha_h;
    let b = weighted_dot(w, g_h, g_d);
    let d = weighted_dot(w, g_d, g_d) + alpha_d;
    // Scale the system to O(1) before the determinant so tiny stiff tets stay in f32 range.
    let s = 1.0 / (a + d);
    let (a, b, d) = (a * s, b * s, d * s);
    let det = a * d - b * b;
    if det.is_nan() || det <= 0.0 {
        return 0.0;
    }
    let (r1, r2) = (-c_h * s, -c_d * s);
    let dl_h = (r1 * d - b * r2) / det;
    let dl_d = (a * r2 - b * r1) / det;
    for i in 0..4 {
        x[i] += w[i] * (g_h[i] * dl_h + g_d[i] * dl_d);
    }
    dl_h
}

/// H then D, each a scalar XPBD step (the form written in PHYSICS.md §1.2).
pub(super) fn project_sequential(x: &mut [Vec3; 4], w: &[f32; 4], t: &TetTerms) -> f32 {
    let f = deformation_gradient_from_displacement(x, &t.dm_inv);
    let g_h = vertex_gradients(det_gradient(&f), &t.dm_inv);
    let dl_h = apply_scalar(x, w, &g_h, f.determinant() - t.gamma, t.alpha_h);
    let f = deformation_gradient_from_displacement(x, &t.dm_inv);
    let norm =
        (f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared()).sqrt();
    if norm >= 1e-12 {
        let g_d = vertex_gradients(f * (1.0 / norm), &t.dm_inv);
        apply_scalar(x, w, &g_d, norm, t.alpha_d);
    }
    dl_h
}

/// One scalar XPBD update: `Δλ = −C / (Σ w|∇C|² + α̃)`, `x_i += w_i ∇_i C Δλ`.
// PHYSICS.md §1.2, XPBD update with λ = 0 at the start of the substep.
#[inline]
pub(super) fn apply_scalar(
    x: &mut [Vec3; 4],
    w: &[f32; 4],
    g: &[Vec3; 4],
    c: f32,
    alpha: f32,
) -> f32 {
    let denom = weighted_dot(w, g, g) + alpha;
    if denom.is_nan() || denom <= 0.0 {
        return 0.0;
    }
    let dl = -c / denom;
    for i in 0..4 {
        x[i] += w[i] * g[i] * dl;
    }
    dl
}

#[cfg(test)]
mod tests {
    use super::*;

    fn terms(alpha: f32, gamma: f32) -> TetTerms {
        TetTerms::uniform(alpha, gamma)
    }

    #[test]
    fn det_gradient_matches_finite_differences() {
        let f = Mat3::from_cols_array(&[1.1, 0.2, -0.1, 0.05, 0.9, 0.3, 0.0, -0.2, 1.2]);
        let g = det_gradient(&f);
        let eps = 1e-3;
        for c in 0..3 {
            for r in 0..3 {
                let mut fp = f;
                fp.col_mut(c)[r] += eps;
                let mut fm = f;
                fm.col_mut(c)[r] -= eps;
                let fd = (fp.determinant() - fm.determinant()) / (2.0 * eps);
                assert!(
                    (fd - g.col(c)[r]).abs() < 1e-3,
                    "({r},{c}) {fd} vs {}",
                    g.col(c)[r]
                );
            }
        }
    }

    #[test]
    fn coupled_projection_keeps_the_rest_state_of_a_tet() {
        // μ = λ: α̃_H = α̃_D, γ = 2. Displacements start at zero (the rest state).
        let mut u = [Vec3::ZERO; 4];
        project_coupled(&mut u, &[1.0; 4], &terms(0.5, 2.0));
        for a in &u {
            assert!(a.length() < 1e-6, "a node moved by {a}");
        }
    }

    #[test]
    fn stiff_projection_restores_volume_of_a_squashed_tet() {
        // γ = 1 (λ → ∞ limit), tiny compliance: a few steps bring det F near 1. Rest tet
        // (0, X, Y, Z) with Dm = I, squashed to half height: u_3 = −Z/2.
        let mut x = [Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::Z * -0.5];
        let t = TetTerms {
            dm_inv: Mat3::IDENTITY,
            alpha_h: 1e-6,
            alpha_d: 1e6,
            gamma: 1.0,
        };
        for _ in 0..20 {
            project_coupled(&mut x, &[1.0; 4], &t);
        }
        let det = deformation_gradient_from_displacement(&x, &Mat3::IDENTITY).determinant();
        assert!((det - 1.0).abs() < 1e-3, "det {det}");
    }
}
