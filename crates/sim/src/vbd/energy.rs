//! Per-vertex force and 3×3 Hessian of the compressible Neo-Hookean energy of the
//! rest-free pair, `Ψ = μ/2 (I_C − 3) − μ L(J) + λ/2 L(J)²` (Bonet & Wood 2008, eq. 6.28;
//! `L = ln J`, continued linearly below `J_MIN` exactly as [`crate::xpbd::log_volume`]).
//!
//! VBD needs, for the vertex `i` of each incident tet, `∂E/∂x_i` and the diagonal block
//! `∂²E/∂x_i²` (Chen et al. 2024, §3.2, the local system `f_i`, `H_i`). With `F = I + H`,
//! `H = Du Dm⁻¹` and `b_i = ∂F/∂x_i` (row `i` of `Dm⁻¹`, `b_0 = −b_1 − b_2 − b_3`):
//!
//! ```text
//! P       = μ (F − L' cof F) + λ L L' cof F                 (first Piola–Kirchhoff)
//! ∂E/∂x_i = V P b_i
//! ∂²E/∂x_i² = V [ μ |b_i|² I + c (cof F b_i)(cof F b_i)ᵀ ],   c = λ L'² + (λ L − μ) L''
//! ```
//!
//! The `∂ cof F/∂F` term contracts to zero with `b_i` on both sides (it is
//! antisymmetric in the pair of `b` indices), so this block is exact, not an
//! approximation, whenever `c ≥ 0` (i.e. `J ≤ e^{1 + μ/λ}` above `J_MIN`). Where `c < 0`
//! it is clamped to zero, the PSD projection: the block then stays SPD because of the
//! `μ |b|² I` term. Everything is evaluated from `H` ([`Strain`]), so rest is exactly
//! force-free in f32.

use glam::{Mat3, Vec3};

use crate::material::Lame;
use crate::xpbd::{J_MIN, Strain, log_volume, shape_energy};

/// `∂F/∂x_i` of the four nodes of a tet with inverse rest shape matrix `dm_inv`.
#[inline]
pub fn shape_gradients(dm_inv: &Mat3) -> [Vec3; 4] {
    let t = dm_inv.transpose();
    let (b1, b2, b3) = (t.x_axis, t.y_axis, t.z_axis);
    [-(b1 + b2 + b3), b1, b2, b3]
}

/// Energy density `Ψ(F)` at the strain `s`, J/m³ (`μ/2 ψ̂ + λ/2 L²`, both terms from `H`).
#[inline]
pub fn energy_density(s: &Strain, lame: Lame) -> f32 {
    let (psi_hat, _) = shape_energy(s);
    let (l, _) = log_volume(s);
    0.5 * lame.mu * psi_hat + 0.5 * lame.lambda * l * l
}

/// First Piola–Kirchhoff stress `P = ∂Ψ/∂F` at the strain `s`, Pa.
#[inline]
pub fn piola(s: &Strain, lame: Lame) -> Mat3 {
    // shape_energy's half gradient is F − L' cof F, evaluated from H.
    let (_, half) = shape_energy(s);
    let (l, dl) = log_volume(s);
    half * lame.mu + s.cof_f() * (lame.lambda * l * dl)
}

/// Gradient `∂E/∂x_i` and PSD diagonal Hessian block `∂²E/∂x_i²` of one tet's energy
/// `E = V Ψ` for its node with shape gradient `b` (see the module docs).
#[inline]
pub fn vertex_gradient_hessian(s: &Strain, lame: Lame, volume: f32, b: Vec3) -> (Vec3, Mat3) {
    let (l, dl) = log_volume(s);
    let (_, half) = shape_energy(s);
    let cof = s.cof_f();
    let p = half * lame.mu + cof * (lame.lambda * l * dl);
    let grad = p * b * volume;
    let ddl = if s.j() > J_MIN { -dl * dl } else { 0.0 };
    let c = (lame.lambda * dl * dl + (lame.lambda * l - lame.mu) * ddl).max(0.0);
    let cb = cof * b;
    let hess = Mat3::IDENTITY * (lame.mu * b.length_squared() * volume)
        + Mat3::from_cols(cb * cb.x, cb * cb.y, cb * cb.z) * (c * volume);
    (grad, hess)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rest_is_force_free_and_the_block_is_spd() {
        let lame = Lame {
            mu: 6.0e4,
            lambda: 5.4e5,
        };
        let s = Strain::of(Mat3::ZERO);
        let (g, h) = vertex_gradient_hessian(&s, lame, 1e-9, Vec3::new(300.0, -100.0, 50.0));
        assert_eq!(g, Vec3::ZERO);
        assert!(h.determinant() > 0.0);
        assert_eq!(energy_density(&s, lame), 0.0);
    }
}
