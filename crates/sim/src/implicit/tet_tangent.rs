//! The tangent of the rest-free Neo-Hookean stress: `dP[dF]`, what one Newton step needs
//! to multiply the Hessian of the elastic energy by a direction (matrix-free).
//!
//! With `P = μ F + s₃ cof F`, `s₃ = (λ L − μ) L'` ([`crate::vbd::piola`], L = ln J
//! continued linearly below `J_MIN` as [`crate::xpbd::log_volume`]):
//!
//! ```text
//! dP[dF] = μ dF + c (cof F : dF) cof F + s₃ dcof[dF],   c = λ L'² + (λ L − μ) L''
//! dcof[dF] = [df₂×f₃ + f₂×df₃, df₃×f₁ + f₃×df₁, df₁×f₂ + f₁×df₂]   (columns)
//! ```
//!
//! This is the exact second derivative (PHYSICS.md §1.2's energy, differentiated twice),
//! not a projection: it is positive definite near rest and may lose definiteness under
//! large compression, which the conjugate gradient notices and stops at
//! ([`super::pcg`]).

use glam::Mat3;

use crate::material::Lame;
use crate::xpbd::{J_MIN, Strain, log_volume};

/// A tet's stress tangent at its current deformation.
#[derive(Debug, Clone, Copy)]
pub struct TetTangent {
    /// `F = I + H`.
    f: Mat3,
    /// `cof F`.
    cof: Mat3,
    /// μ, Pa.
    mu: f32,
    /// `λ L'² + (λ L − μ) L''`, Pa.
    c: f32,
    /// `(λ L − μ) L'`, Pa.
    s3: f32,
}

impl TetTangent {
    /// The tangent at the strain `s`.
    #[inline]
    pub fn at(s: &Strain, lame: Lame) -> Self {
        let (l, dl) = log_volume(s);
        let ddl = if s.j() > J_MIN { -dl * dl } else { 0.0 };
        let pressure = lame.lambda * l - lame.mu;
        let f = Mat3::IDENTITY + s.h;
        TetTangent {
            f,
            cof: s.cof_f(),
            mu: lame.mu,
            c: lame.lambda * dl * dl + pressure * ddl,
            s3: pressure * dl,
        }
    }

    /// The tangent at rest (linear elasticity).
    pub fn at_rest(lame: Lame) -> Self {
        Self::at(&Strain::of(Mat3::ZERO), lame)
    }

    /// `dP[dF]`, Pa.
    #[inline]
    pub fn dp(&self, df: &Mat3) -> Mat3 {
        let dj = frobenius(&self.cof, df);
        *df * self.mu + self.cof * (self.c * dj) + cofactor_differential(&self.f, df) * self.s3
    }

    /// This tangent with its indefinite parts cut, `c ≥ 0` and `s₃ ≥ −μ/σ̂` (σ̂ ≥ 1 a
    /// Gershgorin bound of the largest stretch, `largest_stretch_bound`; at rest nothing
    /// is cut): positive semi-definite, what the preconditioner's matrices hold.
    #[inline]
    pub fn definite(&self) -> Self {
        TetTangent {
            c: self.c.max(0.0),
            s3: self.s3.max(-self.mu / largest_stretch_bound(&self.f)),
            ..*self
        }
    }

    /// The tangent of the parts [`TetTangent::parts`] gives.
    #[inline]
    pub(crate) fn from_parts(f: Mat3, cof: Mat3, mu: f32, c: f32, s3: f32) -> Self {
        TetTangent { f, cof, mu, c, s3 }
    }

    /// `(F, cof F, μ, c, s₃)`: what the eight-lane product ([`super::product_lanes`]) packs.
    #[inline]
    pub(crate) fn parts(&self) -> (Mat3, Mat3, f32, f32, f32) {
        (self.f, self.cof, self.mu, self.c, self.s3)
    }

    /// `∂²E/∂x_a²` of a tet of volume `volume` for its node with shape gradient `b`,
    /// with `c` clamped at zero (a positive definite block: the block Jacobi part of the
    /// preconditioner). The `dcof` term contracts to zero with `b` on both sides.
    #[inline]
    pub fn diagonal_block(&self, volume: f32, b: glam::Vec3) -> Mat3 {
        let cb = self.cof * b;
        Mat3::IDENTITY * (self.mu * b.length_squared() * volume)
            + Mat3::from_cols(cb * cb.x, cb * cb.y, cb * cb.z) * (self.c.max(0.0) * volume)
    }
}

/// `A : B = Σ A_ij B_ij`.
#[inline]
fn frobenius(a: &Mat3, b: &Mat3) -> f32 {
    a.x_axis.dot(b.x_axis) + a.y_axis.dot(b.y_axis) + a.z_axis.dot(b.z_axis)
}

/// The derivative of `cof F` in the direction `dF`.
#[inline]
fn cofactor_differential(f: &Mat3, df: &Mat3) -> Mat3 {
    Mat3::from_cols(
        df.y_axis.cross(f.z_axis) + f.y_axis.cross(df.z_axis),
        df.z_axis.cross(f.x_axis) + f.z_axis.cross(df.x_axis),
        df.x_axis.cross(f.y_axis) + f.x_axis.cross(df.y_axis),
    )
}

/// `σ̂ ≥ σ_max(F)`, at least 1: the square root of the largest absolute row sum of `FᵀF`
/// (Gershgorin); exactly 1 at rest.
#[inline]
fn largest_stretch_bound(f: &Mat3) -> f32 {
    let c = f.transpose() * *f;
    let row = |r: usize| (0..3).map(|k| c.col(k)[r].abs()).sum::<f32>();
    row(0).max(row(1)).max(row(2)).sqrt().max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vbd::piola;
    use crate::xpbd::cofactor;

    fn max_abs(m: Mat3) -> f32 {
        m.to_cols_array().iter().fold(0.0f32, |a, b| a.max(b.abs()))
    }

    fn lame() -> Lame {
        Lame {
            mu: 6.2e4,
            lambda: 5.59e5,
        }
    }

    /// dP against central differences of `piola` at a sheared, stretched state.
    #[test]
    fn the_tangent_is_the_derivative_of_the_stress() {
        let h = Mat3::from_cols_array(&[0.3, -0.1, 0.05, 0.2, 0.15, -0.05, 0.1, 0.02, -0.2]);
        let df = Mat3::from_cols_array(&[0.2, 0.5, -0.3, 0.1, -0.4, 0.25, 0.3, 0.1, 0.6]);
        let t = TetTangent::at(&Strain::of(h), lame());
        let eps = 1e-3;
        let fd = (piola(&Strain::of(h + df * eps), lame())
            - piola(&Strain::of(h - df * eps), lame()))
            * (0.5 / eps);
        let (worst, scale) = (max_abs(t.dp(&df) - fd), max_abs(fd));
        assert!(worst < 2e-2 * scale, "dP off by {worst} of {scale}");
        // The cofactor identity the tangent relies on.
        let f = Mat3::IDENTITY + h;
        assert!(max_abs(cofactor(&f) - Strain::of(h).cof_f()) < 1e-5);
    }

    /// At rest the tangent is linear elasticity: dP = μ(dF + dFᵀ) + λ tr(dF) I.
    #[test]
    fn at_rest_the_tangent_is_linear_elasticity() {
        let df = Mat3::from_cols_array(&[0.2, 0.5, -0.3, 0.1, -0.4, 0.25, 0.3, 0.1, 0.6]);
        let t = TetTangent::at(&Strain::of(Mat3::ZERO), lame());
        let tr = df.x_axis.x + df.y_axis.y + df.z_axis.z;
        let want = (df + df.transpose()) * lame().mu + Mat3::IDENTITY * (lame().lambda * tr);
        assert!(max_abs(t.dp(&df) - want) < 1e-6 * lame().lambda);
    }
}
