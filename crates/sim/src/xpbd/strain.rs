//! Invariants of `F = I + H` evaluated from the displacement gradient `H = Du Dm⁻¹`
//! without cancellation (docs/physics-notes.md, "Rest-free Neo-Hookean").
//!
//! Near rest `‖F‖² − 3`, `det F − 1` and `F − F⁻ᵀ` are differences of numbers close to one:
//! in f32 they lose everything below ~1e-7, which is the whole strain of a tissue resting
//! under its own weight. Written as polynomials in `H` they are exact to rounding at any
//! strain, so a rest-free constraint is exactly zero at rest and smooth near it.

use glam::Mat3;

use crate::mesh::shape_matrix;

/// Below this `|J − 1|`, `x − ln(1 + x)` is evaluated by its series.
pub(super) const SERIES_LIMIT: f32 = 0.1;

/// `H = Du Dm⁻¹` from the four nodes' displacements.
// PHYSICS.md §1.2, F = Ds Dm^-1 = I + Du Dm^-1.
#[inline]
pub fn displacement_gradient(u: &[glam::Vec3; 4], dm_inv: &Mat3) -> Mat3 {
    shape_matrix(u[0], u[1], u[2], u[3]) * *dm_inv
}

/// Cofactor matrix `cof A = [a2×a3, a3×a1, a1×a2]` (columns); `cof F = ∂det F/∂F`.
#[inline]
pub fn cofactor(a: &Mat3) -> Mat3 {
    Mat3::from_cols(
        a.y_axis.cross(a.z_axis),
        a.z_axis.cross(a.x_axis),
        a.x_axis.cross(a.y_axis),
    )
}

/// `F = I + H` and its invariants, each computed from `H`.
#[derive(Debug, Clone, Copy)]
pub struct Strain {
    /// Displacement gradient `H = F − I`.
    pub h: Mat3,
    /// `tr H`.
    pub tr: f32,
    /// Second invariant of `H`: `½((tr H)² − tr(H²))`.
    pub i2: f32,
    /// `det H`.
    pub det_h: f32,
    /// `J − 1 = tr H + I₂(H) + det H` (exact expansion of `det(I + H) − 1`).
    pub j1: f32,
    /// `cof H`.
    pub cof_h: Mat3,
}

impl Strain {
    /// The invariants of `I + h`.
    #[inline]
    pub fn of(h: Mat3) -> Self {
        let tr = h.x_axis.x + h.y_axis.y + h.z_axis.z;
        let h2 = h * h;
        let tr_h2 = h2.x_axis.x + h2.y_axis.y + h2.z_axis.z;
        let i2 = 0.5 * (tr * tr - tr_h2);
        let det_h = h.determinant();
        Strain {
            h,
            tr,
            i2,
            det_h,
            j1: tr + i2 + det_h,
            cof_h: cofactor(&h),
        }
    }

    /// `J = det F`.
    #[inline]
    pub fn j(&self) -> f32 {
        1.0 + self.j1
    }

    /// `‖H‖²_F`.
    #[inline]
    pub fn h_norm2(&self) -> f32 {
        self.h.x_axis.length_squared()
            + self.h.y_axis.length_squared()
            + self.h.z_axis.length_squared()
    }

    /// `cof F = (1 + tr H) I − Hᵀ + cof H` (the 3×3 identity for `cof(I + H)`).
    #[inline]
    pub fn cof_f(&self) -> Mat3 {
        Mat3::IDENTITY * (1.0 + self.tr) - self.h.transpose() + self.cof_h
    }

    /// `J F − cof F = (I₂ + det H) I + H + Hᵀ + (J − 1) H − cof H`: `J (F − F⁻ᵀ)`.
    #[inline]
    pub fn j_f_minus_cof(&self) -> Mat3 {
        Mat3::IDENTITY * (self.i2 + self.det_h) + self.h + self.h.transpose() + self.h * self.j1
            - self.cof_h
    }

    /// `F Fᵀ − I = H + Hᵀ + H Hᵀ` (left Cauchy–Green tensor less the identity).
    #[inline]
    pub fn b_minus_i(&self) -> Mat3 {
        self.h + self.h.transpose() + self.h * self.h.transpose()
    }
}

/// `x − ln(1 + x)` for `x > −1`, accurate near 0 (series below `SERIES_LIMIT`); the
/// same operations as `log1p_excess` in `gpu/shaders/neo_hookean.wgsl`.
#[inline]
pub fn log1p_excess(x: f32) -> f32 {
    if x.abs() < SERIES_LIMIT {
        // x²/2 − x³/3 + … + x⁸/8: truncation below 3e-8 relative at |x| = 0.1.
        let x2 = x * x;
        let tail = -1.0 / 7.0 + x * 0.125;
        let tail = -0.2 + x * (1.0 / 6.0 + x * tail);
        x2 * (0.5 + x * (-1.0 / 3.0 + x * (0.25 + x * tail)))
    } else {
        x - (1.0 + x).ln()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Mat3 {
        Mat3::from_cols_array(&[0.11, -0.05, 0.02, 0.07, -0.13, 0.04, -0.03, 0.09, 0.21])
    }

    #[test]
    fn invariants_match_the_direct_forms() {
        let h = sample();
        let s = Strain::of(h);
        let f = Mat3::IDENTITY + h;
        assert!((s.j() - f.determinant()).abs() < 1e-6);
        let cof = cofactor(&f);
        assert!((s.cof_f() - cof).abs_diff_eq(Mat3::ZERO, 1e-6));
        let direct = f * f.determinant() - cof;
        assert!((s.j_f_minus_cof() - direct).abs_diff_eq(Mat3::ZERO, 1e-6));
        assert!(
            (s.b_minus_i() - (f * f.transpose() - Mat3::IDENTITY)).abs_diff_eq(Mat3::ZERO, 1e-6)
        );
    }

    /// At strains of 1e-7 the direct forms are noise in f32; the H forms keep their
    /// leading order (here `J − 1 = tr H` to 1e-6 relative).
    #[test]
    fn tiny_strain_keeps_its_digits() {
        let h = sample() * 1e-6;
        let s = Strain::of(h);
        let tr = h.x_axis.x + h.y_axis.y + h.z_axis.z;
        assert!(((s.j1 - tr) / tr).abs() < 1e-5, "{} vs {tr}", s.j1);
        let direct = (Mat3::IDENTITY + h).determinant() - 1.0;
        assert!(
            ((direct - tr) / tr).abs() > 1e-3,
            "f32 det F − 1 unexpectedly exact"
        );
    }

    #[test]
    fn log1p_excess_matches_f64() {
        // The series to 1e-6 relative; the direct form just past it loses ~1e-5 to the
        // rounding of 1 + x (harmless: it is a term of C_D², of order strain²).
        for x in [
            -0.6f32, -0.2, -0.099, -1e-3, 0.0, 2e-4, 0.0999, 0.1, 0.3, 2.0,
        ] {
            let exact = x as f64 - (x as f64).ln_1p();
            let got = log1p_excess(x) as f64;
            let rel = if x.abs() < SERIES_LIMIT { 1e-6 } else { 3e-5 };
            let tol = rel * exact.abs() + 1e-12;
            assert!((got - exact).abs() <= tol, "x = {x}: {got} vs {exact}");
        }
    }
}
