//! The Cauchy (true) stress of the solver's own Neo-Hookean energy at a tet's `F`, and its
//! von Mises value (docs/physics-notes.md, "True stress").
//!
//! Both constraint pairs share the deviatoric term, `dev σ = (μ/J) dev(F Fᵀ)`; they differ
//! in the pressure:
//!
//! ```text
//! rest-free      σ = (μ/J)(F Fᵀ − I) + λ L(J) L'(J) I + μ (1/J − L'(J)) I
//! γ-shifted      σ = (μ/J)(F Fᵀ − I) + (J − 1)(λ_H − μ/J) I
//! ```
//!
//! (`P = ∂Ψ/∂F`, `σ = P Fᵀ / J`; `L = ln J` above `J_MIN`, so the rest-free pressure is
//! `λ ln J / J` there.) Everything is evaluated from `H = F − I` ([`Strain`]), so a tet at
//! rest reports exactly zero and a 1e-6 strain keeps its digits. No polar decomposition is
//! needed; the seed's eq. 3 (which needs one) is [`super::tet_stress`].

use glam::Mat3;

use crate::material::Lame;
use crate::xpbd::{ConstraintPair, J_MIN, Strain, log_volume};

/// Which stress the solver reports, draws and compares with the release threshold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum StressMeasure {
    /// The Cauchy stress of the model's energy at `F` (default).
    #[default]
    Cauchy,
    /// The seed paper's eq. 3, `μ((RᵀF + FᵀR)/2 − I) + λ_H/(h²V) I` (PHYSICS.md §1.3):
    /// about half the Cauchy stress in uniaxial tension; kept to reproduce the paper.
    PaperEq3,
}

/// Cauchy stress of `pair` with Lamé `lame` (`lambda_h`: the γ-shifted pair's volume
/// stiffness) at the strain `s`, Pa. Below `J_MIN` the `1/J` factor is taken at `J_MIN`
/// (an inverted tet has no Cauchy stress; the inversion guard handles it).
// docs/physics-notes.md, true stress: σ = P Fᵀ / J.
#[inline]
pub fn cauchy_stress(s: &Strain, lame: Lame, pair: ConstraintPair, lambda_h: f32) -> Mat3 {
    let inv_j = 1.0 / s.j().max(J_MIN);
    let shape = s.b_minus_i() * (lame.mu * inv_j);
    let pressure = match pair {
        ConstraintPair::RestFree => {
            let (l, dl) = log_volume(s);
            lame.lambda * l * dl + lame.mu * (inv_j - dl)
        }
        ConstraintPair::GammaShifted => s.j1 * (lambda_h - lame.mu * inv_j),
    };
    shape + Mat3::IDENTITY * pressure
}

/// von Mises stress `sqrt(3/2) ‖dev σ‖_F` of a symmetric stress.
// PHYSICS.md §1.3, seed eq. (4).
#[inline]
pub fn von_mises(sigma: &Mat3) -> f32 {
    let mean = (sigma.x_axis.x + sigma.y_axis.y + sigma.z_axis.z) / 3.0;
    let dev = *sigma - Mat3::IDENTITY * mean;
    let n2 =
        dev.x_axis.length_squared() + dev.y_axis.length_squared() + dev.z_axis.length_squared();
    (1.5 * n2).sqrt()
}

/// Mean normal stress `tr σ / 3`, Pa.
pub fn mean_stress(sigma: &Mat3) -> f32 {
    (sigma.x_axis.x + sigma.y_axis.y + sigma.z_axis.z) / 3.0
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::material::Material;

    fn lame(nu: f32) -> Lame {
        Material {
            youngs_modulus: 60e3,
            poisson_ratio: nu,
            density: 1000.0,
        }
        .lame()
    }

    fn strain(f: Mat3) -> Strain {
        Strain::of(f - Mat3::IDENTITY)
    }

    /// σ = ∂Ψ/∂F Fᵀ / J against f64 finite differences of the energy, both pairs.
    #[test]
    fn cauchy_stress_is_the_energy_derivative() {
        let f = Mat3::from_cols_array(&[1.2, 0.1, -0.05, 0.08, 0.93, 0.12, 0.02, -0.1, 1.1]);
        let l = lame(0.4);
        let (mu, lam) = (l.mu as f64, l.lambda as f64);
        let lh = lam + mu;
        let gamma = 1.0 + mu / lh;
        let det = |f: &[[f64; 3]; 3]| {
            f[0][0] * (f[1][1] * f[2][2] - f[2][1] * f[1][2])
                - f[1][0] * (f[0][1] * f[2][2] - f[2][1] * f[0][2])
                + f[2][0] * (f[0][1] * f[1][2] - f[1][1] * f[0][2])
        };
        type Energy = Box<dyn Fn(&[[f64; 3]; 3]) -> f64>;
        let energies: [(ConstraintPair, Energy); 2] = [
            (
                ConstraintPair::RestFree,
                Box::new(move |f| {
                    let ic: f64 = f.iter().flatten().map(|v| v * v).sum();
                    let j = det(f);
                    0.5 * mu * (ic - 3.0) - mu * j.ln() + 0.5 * lam * j.ln().powi(2)
                }),
            ),
            (
                ConstraintPair::GammaShifted,
                Box::new(move |f| {
                    let ic: f64 = f.iter().flatten().map(|v| v * v).sum();
                    0.5 * mu * ic + 0.5 * lh * (det(f) - gamma).powi(2)
                }),
            ),
        ];
        let cols = f.to_cols_array_2d().map(|c| c.map(|v| v as f64));
        for (pair, psi) in energies {
            let sigma = cauchy_stress(&strain(f), l, pair, lh as f32);
            // P by central differences (P[c][r] = ∂Ψ/∂F_rc), then σ = P Fᵀ / J.
            let mut p = [[0.0f64; 3]; 3];
            let eps = 1e-6;
            for c in 0..3 {
                for r in 0..3 {
                    let (mut a, mut b) = (cols, cols);
                    a[c][r] += eps;
                    b[c][r] -= eps;
                    p[c][r] = (psi(&a) - psi(&b)) / (2.0 * eps);
                }
            }
            let j = det(&cols);
            #[allow(clippy::needless_range_loop)] // r, c index two matrices at once
            for r in 0..3 {
                for c in 0..3 {
                    let expect: f64 = (0..3).map(|k| p[k][r] * cols[k][c]).sum::<f64>() / j;
                    let got = sigma.col(c)[r] as f64;
                    assert!(
                        (got - expect).abs() < 2e-4 * mu,
                        "{pair:?} σ[{r}][{c}] = {got} vs {expect}"
                    );
                }
            }
        }
    }

    #[test]
    fn rest_has_no_stress_and_tiny_strain_is_linear() {
        for pair in [ConstraintPair::RestFree, ConstraintPair::GammaShifted] {
            let l = lame(0.45);
            let lh = l.lambda + l.mu;
            assert_eq!(
                cauchy_stress(&strain(Mat3::IDENTITY), l, pair, lh),
                Mat3::ZERO
            );
            // Linear elasticity at ε = 1e-6 shear: σ_xy = 2 μ ε.
            let mut h = Mat3::ZERO;
            h.y_axis.x = 1e-6;
            h.x_axis.y = 1e-6;
            let sigma = cauchy_stress(&Strain::of(h), l, pair, lh);
            let expect = 2.0 * l.mu * 1e-6;
            assert!(
                ((sigma.y_axis.x - expect) / expect).abs() < 1e-4,
                "{pair:?}"
            );
        }
    }

    /// Uniaxial stretch with the lateral stretch that leaves the sides free: von Mises is
    /// the axial stress, and at small strain E ε.
    #[test]
    fn free_uniaxial_small_strain_is_youngs_modulus() {
        let l = lame(0.3);
        let e = 1e-3f32;
        let lateral = 1.0 - 0.3 * e;
        let f = Mat3::from_diagonal(Vec3::new(1.0 + e, lateral, lateral));
        let sigma = cauchy_stress(&strain(f), l, ConstraintPair::RestFree, 0.0);
        let vm = von_mises(&sigma);
        assert!((vm / (60e3 * e) - 1.0).abs() < 2e-3, "σ_vM = {vm}");
        assert!(sigma.y_axis.y.abs() < 1e-3 * sigma.x_axis.x);
    }
}
