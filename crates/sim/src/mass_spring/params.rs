//! Parameters of the tension mass-spring model (PHYSICS.md §2.1–2.2) and their checks.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::{StiffnessLaw, Tension};

/// Physical parameters of the mass-spring model, SI units.
///
/// Defaults are the Nakao 2003 plate: k = 100 N/m, b = 0.05 N·s/m, ρ = 0.9 g/cm³.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MassSpringParams {
    /// Spring constant k of every edge, N/m (PHYSICS.md §2.1).
    pub stiffness: f64,
    /// How each edge's constant follows from `stiffness` and the mesh (the paper's
    /// `Uniform`, or the default `TetVolume`, which keeps a split region's stiffness).
    pub stiffness_law: StiffnessLaw,
    /// Node damping coefficient b in `F_diss = −b v`, N·s/m (PHYSICS.md §2.1).
    pub damping: f64,
    /// Density ρ for the node masses of eq. 4, kg/m³.
    pub density: f64,
    /// Gravity g, m/s².
    pub gravity: DVec3,
    /// Tension coefficients s of eq. 3 (uniform or per direction).
    pub tension: Tension,
    /// Largest integration step, s; the model takes smaller steps when the stability bound asks.
    pub max_dt: f64,
}

impl Default for MassSpringParams {
    fn default() -> Self {
        MassSpringParams {
            stiffness: 100.0,
            stiffness_law: StiffnessLaw::TetVolume,
            damping: 0.05,
            density: 900.0,
            gravity: DVec3::new(0.0, 0.0, -9.81),
            tension: Tension::Uniform(0.0),
            max_dt: 1.0e-3,
        }
    }
}

/// Why mass-spring parameters or inputs are unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MassSpringError {
    /// A parameter is out of range; names the field.
    #[error("{field} {msg}")]
    BadParameter {
        /// Field name.
        field: &'static str,
        /// What is wrong.
        msg: String,
    },
    /// A node index is past the node count.
    #[error("node index {index} is out of range (the model has {count} nodes)")]
    NodeOutOfRange {
        /// The index.
        index: u32,
        /// Node count.
        count: usize,
    },
    /// A saved dynamic state does not fit the model (a cut added nodes since it was saved).
    #[error("the saved state has {saved} nodes but the model has {nodes}")]
    StateMismatch {
        /// Nodes of the saved state.
        saved: usize,
        /// Nodes of the model.
        nodes: usize,
    },
    /// The mesh has a tet of non-positive volume.
    #[error("tet {tet} has non-positive volume {volume:e} m^3")]
    BadTet {
        /// Tet index.
        tet: usize,
        /// Its signed volume.
        volume: f64,
    },
}

impl MassSpringParams {
    /// Check every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), MassSpringError> {
        let bad = |field, msg: String| Err(MassSpringError::BadParameter { field, msg });
        if !(self.stiffness.is_finite() && self.stiffness > 0.0) {
            return bad(
                "stiffness",
                format!(
                    "must be a positive spring constant in N/m, got {}",
                    self.stiffness
                ),
            );
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return bad(
                "damping",
                format!("must be >= 0 N·s/m, got {}", self.damping),
            );
        }
        if !(self.density.is_finite() && self.density > 0.0) {
            return bad(
                "density",
                format!("must be a positive density in kg/m^3, got {}", self.density),
            );
        }
        if !self.gravity.is_finite() {
            return bad("gravity", format!("must be finite, got {}", self.gravity));
        }
        if !(self.max_dt.is_finite() && self.max_dt > 0.0) {
            return bad(
                "max_dt",
                format!("must be a positive time step in s, got {}", self.max_dt),
            );
        }
        if let Err(msg) = self.tension.validate() {
            return bad("tension", msg);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_fields_are_named() {
        assert!(MassSpringParams::default().validate().is_ok());
        let p = MassSpringParams {
            damping: -1.0,
            ..MassSpringParams::default()
        };
        let e = p.validate().unwrap_err().to_string();
        assert!(e.starts_with("damping"), "{e}");
        let p = MassSpringParams {
            tension: Tension::Uniform(1.0),
            ..MassSpringParams::default()
        };
        assert!(p.validate().unwrap_err().to_string().starts_with("tension"));
    }
}
