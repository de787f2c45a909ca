//! Isotropic hyperelastic material parameters (PHYSICS.md §1.1).

use serde::{Deserialize, Serialize};

/// Young's modulus, Poisson ratio and density of a tissue, SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus E, Pa.
    pub youngs_modulus: f32,
    /// Poisson ratio ν, in (−1, 0.5).
    pub poisson_ratio: f32,
    /// Density ρ, kg/m³.
    pub density: f32,
}

/// Lamé parameters derived from a [`Material`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lame {
    /// Shear modulus μ, Pa.
    pub mu: f32,
    /// First Lamé parameter λ, Pa.
    pub lambda: f32,
}

/// Why a material is unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MaterialError {
    /// E must be positive and finite.
    #[error("youngs_modulus must be a positive number of pascals, got {0}")]
    YoungsModulus(f32),
    /// ν must lie in the open interval (−1, 0.5).
    #[error("poisson_ratio must lie strictly between -1 and 0.5, got {0}")]
    PoissonRatio(f32),
    /// ρ must be positive and finite.
    #[error("density must be a positive number of kg/m^3, got {0}")]
    Density(f32),
}

/// Which stiffness the hydrostatic constraint `C_H = det F − γ` uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum HydrostaticStiffness {
    /// `λ_H = λ`, as PHYSICS.md §1.2 and the seed paper write it. The γ-shifted energy then
    /// linearises to Lamé (μ, λ − μ): ≈ 10 % too soft at ν = 0.3, and a negative bulk
    /// modulus for ν ≤ 1/8 (docs/physics-notes.md).
    #[default]
    Lambda,
    /// `λ_H = λ + μ` (Smith et al. 2018, "Stable Neo-Hookean Flesh Simulation", §3.4): the
    /// linearised material is exactly the one E and ν describe.
    LambdaPlusMu,
}

impl Lame {
    /// Stiffness `λ_H` of the hydrostatic constraint.
    ///
    /// `μ/2 tr(FᵀF) + λ_H/2 (det F − γ)²` expands to `μ/2 (I_C − 3) − μ(J − 1) +
    /// λ_H/2 (J − 1)²`; since `−μ(J − 1) = −μ ln J − μ/2 (J − 1)² + O((J−1)³)`, its
    /// small-strain bulk term is `λ_H − μ`.
    pub fn hydrostatic(&self, mode: HydrostaticStiffness) -> f32 {
        match mode {
            HydrostaticStiffness::Lambda => self.lambda,
            HydrostaticStiffness::LambdaPlusMu => self.lambda + self.mu,
        }
    }

    /// Rest-state shift `γ = 1 + μ/λ_H` of the hydrostatic constraint (PHYSICS.md §1.2).
    pub fn gamma(&self, mode: HydrostaticStiffness) -> f32 {
        1.0 + self.mu / self.hydrostatic(mode)
    }
}

impl Material {
    /// Check the parameter ranges.
    pub fn validate(&self) -> Result<(), MaterialError> {
        if !(self.youngs_modulus.is_finite() && self.youngs_modulus > 0.0) {
            return Err(MaterialError::YoungsModulus(self.youngs_modulus));
        }
        if !(self.poisson_ratio > -1.0 && self.poisson_ratio < 0.5) {
            return Err(MaterialError::PoissonRatio(self.poisson_ratio));
        }
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(MaterialError::Density(self.density));
        }
        Ok(())
    }

    /// `μ = E / (2(1+ν))`, `λ = E ν / ((1+ν)(1−2ν))`.
    // PHYSICS.md §1.1, Lamé parameters.
    pub fn lame(&self) -> Lame {
        let (e, nu) = (self.youngs_modulus as f64, self.poisson_ratio as f64);
        Lame {
            mu: (e / (2.0 * (1.0 + nu))) as f32,
            lambda: (e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))) as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lame_parameters_match_closed_form() {
        let m = Material {
            youngs_modulus: 1.0e4,
            poisson_ratio: 0.25,
            density: 1000.0,
        };
        let l = m.lame();
        assert!((l.mu - 4000.0).abs() < 1e-2);
        assert!((l.lambda - 4000.0).abs() < 1e-2);
    }

    /// The linearised energy with λ_H = λ + μ has bulk modulus λ + 2μ/3 (the one E, ν give),
    /// and with λ_H = λ it has λ − μ + 2μ/3: finite differences of the energy under uniform
    /// dilation.
    #[test]
    fn hydrostatic_stiffness_sets_the_bulk_modulus() {
        for (mode, expect_lambda) in [
            (HydrostaticStiffness::LambdaPlusMu, 0.0f64),
            (HydrostaticStiffness::Lambda, -1.0),
        ] {
            let m = Material {
                youngs_modulus: 1.0e4,
                poisson_ratio: 0.3,
                density: 1000.0,
            };
            let l = m.lame();
            let (lh, g) = (l.hydrostatic(mode) as f64, l.gamma(mode) as f64);
            let mu = l.mu as f64;
            // Energy per volume under uniform dilation F = s I (J = s³).
            let psi = |s: f64| 0.5 * mu * 3.0 * s * s + 0.5 * lh * (s * s * s - g).powi(2);
            let e = 1e-4;
            let d2 = (psi(1.0 + e) - 2.0 * psi(1.0) + psi(1.0 - e)) / (e * e);
            // d²Ψ/ds² at s = 1 under dilation is 9 K.
            let bulk = d2 / 9.0;
            let expect = l.lambda as f64 + expect_lambda * mu + 2.0 * mu / 3.0;
            assert!(
                (bulk - expect).abs() / expect < 1e-3,
                "{mode:?}: bulk {bulk} vs {expect}"
            );
        }
    }

    #[test]
    fn out_of_range_poisson_is_rejected() {
        let m = Material {
            youngs_modulus: 1.0e4,
            poisson_ratio: 0.5,
            density: 1000.0,
        };
        assert_eq!(m.validate(), Err(MaterialError::PoissonRatio(0.5)));
    }
}
