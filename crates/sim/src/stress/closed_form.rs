//! Closed-form stresses of the rest-free Neo-Hookean energy (docs/physics-notes.md, "True
//! stress"), for validation tests and for deriving a scene's release threshold from a
//! tissue's measured failure strain.

use crate::material::Lame;

/// Free uniaxial stretch `a` along x of the rest-free Neo-Hookean solid: the lateral
/// stretch `b` at which the sides carry no stress, and the axial Cauchy stress, Pa.
///
/// `F = diag(a, b, b)`, `σ_yy = (μ/J)(b² − 1) + λ ln J / J = 0` (solved by Newton in
/// f64), `σ_xx = (μ/J)(a² − b²)` — which is also the von Mises stress.
pub fn uniaxial(lame: Lame, a: f64) -> (f64, f64) {
    let (mu, lambda) = (lame.mu as f64, lame.lambda as f64);
    // g(b) = μ(b² − 1) + λ ln(a b²) = 0, increasing in b.
    let mut b = 1.0f64;
    for _ in 0..60 {
        let g = mu * (b * b - 1.0) + lambda * (a * b * b).ln();
        let dg = 2.0 * mu * b + 2.0 * lambda / b;
        let step = g / dg;
        b -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    let j = a * b * b;
    (b, mu / j * (a * a - b * b))
}

/// Cauchy von Mises stress of simple shear `γ` (`F = I + γ e_x ⊗ e_y`, `J = 1`):
/// `σ = μ (F Fᵀ − I)`, `σ_vM = μ sqrt(γ⁴ + 3γ²)`, Pa.
pub fn simple_shear_von_mises(lame: Lame, gamma: f64) -> f64 {
    lame.mu as f64 * (gamma.powi(4) + 3.0 * gamma * gamma).sqrt()
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, Vec3};

    use super::*;
    use crate::material::Material;
    use crate::stress::{cauchy_stress, von_mises};
    use crate::xpbd::{ConstraintPair, Strain};

    fn lame(nu: f32) -> Lame {
        Material {
            youngs_modulus: 180e3,
            poisson_ratio: nu,
            density: 1040.0,
        }
        .lame()
    }

    /// The closed forms agree with the constitutive function at their own `F`.
    #[test]
    fn closed_forms_match_the_cauchy_stress_function() {
        for nu in [0.0f32, 0.3, 0.45, 0.49] {
            let l = lame(nu);
            for a in [1.01f64, 1.3, 2.4] {
                let (b, sxx) = uniaxial(l, a);
                let f = Mat3::from_diagonal(Vec3::new(a as f32, b as f32, b as f32));
                let s = cauchy_stress(
                    &Strain::of(f - Mat3::IDENTITY),
                    l,
                    ConstraintPair::RestFree,
                    0.0,
                );
                assert!(
                    s.y_axis.y.abs() < 1e-4 * sxx as f32,
                    "ν {nu}, a {a}: σ_yy {}",
                    s.y_axis.y
                );
                assert!(((s.x_axis.x as f64 - sxx) / sxx).abs() < 1e-4);
                assert!(((von_mises(&s) as f64 - sxx) / sxx).abs() < 1e-4);
            }
            for g in [0.05f64, 0.3] {
                let mut h = Mat3::ZERO;
                h.y_axis.x = g as f32;
                let s = cauchy_stress(&Strain::of(h), l, ConstraintPair::RestFree, 0.0);
                let expect = simple_shear_von_mises(l, g);
                assert!(((von_mises(&s) as f64 - expect) / expect).abs() < 1e-4);
            }
        }
    }

    /// At small strain, uniaxial stress is E ε and the lateral strain −ν ε.
    #[test]
    fn small_strain_uniaxial_is_hookes_law() {
        let l = lame(0.45);
        let (b, s) = uniaxial(l, 1.0 + 1e-5);
        assert!((s / (180e3 * 1e-5) - 1.0).abs() < 1e-3, "σ = {s}");
        assert!(
            ((1.0 - b) / 1e-5 - 0.45).abs() < 1e-3,
            "ν = {}",
            (1.0 - b) / 1e-5
        );
    }
}
