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
