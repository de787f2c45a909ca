//! A rheological tissue: the constants every edge element of a body region takes, plus its
//! density (PHYSICS.md §3).

use serde::{Deserialize, Serialize};

use super::damper::Damper;
use super::element::ElementParams;

/// Three-element constants and density of one tissue, independent of the mesh.
///
/// The seed gives every edge the same k, c1, c2 (N/m, N·s/m). Here they are per unit
/// length so that one preset behaves alike on coarse and fine meshes: an edge of rest
/// length `L0` gets `k = stiffness·L0`, `c1 = voigt_viscosity·L0`, damper viscosities
/// `× L0` and damper force thresholds `× L0²` (a cubic lattice of spacing L0 under stress
/// σ carries σL0² per edge and strains at `L̇/L0`). Time constants such as `c1/k` are
/// then the same on every edge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RheologyMaterial {
    /// Voigt spring modulus, Pa (per edge `k = stiffness · L0`, N/m).
    pub stiffness: f64,
    /// Voigt damper viscosity, Pa·s (per edge `c1 = voigt_viscosity · L0`, N·s/m).
    pub voigt_viscosity: f64,
    /// Series damper: viscosities in Pa·s, force thresholds in Pa.
    pub damper: Damper,
    /// Voigt ratio a at rest: the Voigt natural length is `l = rest_ratio · L0`.
    pub rest_ratio: f64,
    /// Lower clamp a_min of the Voigt ratio.
    pub ratio_min: f64,
    /// Upper clamp a_max of the Voigt ratio.
    pub ratio_max: f64,
    /// Density ρ, kg/m³ (lumped node masses, PHYSICS.md §1.1).
    pub density: f64,
}

impl RheologyMaterial {
    /// The element constants of an edge of rest length `l0` (m).
    #[inline]
    pub fn element(&self, l0: f64) -> ElementParams {
        ElementParams {
            stiffness: self.stiffness * l0,
            voigt_damping: self.voigt_viscosity * l0,
            damper: self.damper.for_edge(l0),
            ratio_min: self.ratio_min,
            ratio_max: self.ratio_max,
        }
    }

    /// This material with another series damper (e.g. a force-dependent one's linear twin).
    pub fn with_damper(&self, damper: Damper) -> Self {
        RheologyMaterial { damper, ..*self }
    }

    /// The first problem with the parameters as (field, message); `None` when usable.
    pub fn problem(&self) -> Option<(&'static str, String)> {
        let non_negative = |x: f64| x.is_finite() && x >= 0.0;
        if !non_negative(self.stiffness) {
            return Some((
                "stiffness",
                format!("must be >= 0 Pa, got {}", self.stiffness),
            ));
        }
        if !non_negative(self.voigt_viscosity) {
            return Some((
                "voigt_viscosity",
                format!("must be >= 0 Pa·s, got {}", self.voigt_viscosity),
            ));
        }
        if let Some(p) = self.damper.problem() {
            return Some(p);
        }
        let (lo, rest, hi) = (self.ratio_min, self.rest_ratio, self.ratio_max);
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi && hi <= 1.0) {
            return Some((
                "ratio_min",
                format!("needs 0 <= ratio_min <= ratio_max <= 1, got {lo} and {hi}"),
            ));
        }
        if !(rest >= lo && rest <= hi && rest > 0.0) {
            return Some((
                "rest_ratio",
                format!("must lie in (0, 1] between ratio_min {lo} and ratio_max {hi}, got {rest}"),
            ));
        }
        if !(self.density.is_finite() && self.density > 0.0) {
            return Some((
                "density",
                format!("must be a positive number of kg/m^3, got {}", self.density),
            ));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_constants_scale_with_rest_length_and_keep_time_constants() {
        let m = RheologyMaterial {
            stiffness: 1e4,
            voigt_viscosity: 1e3,
            damper: Damper::ForceDependent {
                c_max: 1e6,
                c_min: 1e4,
                f1: 100.0,
                f2: 400.0,
            },
            rest_ratio: 0.9,
            ratio_min: 0.8,
            ratio_max: 1.0,
            density: 1000.0,
        };
        let (a, b) = (m.element(0.01), m.element(0.05));
        assert!((a.stiffness - 100.0).abs() < 1e-9 && (b.stiffness - 500.0).abs() < 1e-9);
        let tau = |e: &ElementParams| e.voigt_damping / e.stiffness;
        assert!((tau(&a) - tau(&b)).abs() < 1e-15);
        let Damper::ForceDependent { f1, c_min, .. } = b.damper else {
            panic!("damper kind changed")
        };
        assert!((f1 - 0.25).abs() < 1e-12 && (c_min - 500.0).abs() < 1e-9);
    }
}
