//! Tension coefficients and the shortened rest lengths of eq. 3 (PHYSICS.md §2.2).

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Tension coefficient `s` of the edges: the rest length is `l = d (1 − s)`, with `d` the
/// edge's length in the reference (initial) configuration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Tension {
    /// The same `s` for every edge, `0 ≤ s < 1`.
    Uniform(f64),
    /// Anisotropic tension: an edge of unit direction `u` gets
    /// `s(u) = s.x u.x² + s.y u.y² + s.z u.z²`, each component in `[0, 1)`.
    PerAxis(DVec3),
}

impl Default for Tension {
    fn default() -> Self {
        Tension::Uniform(0.0)
    }
}

impl Tension {
    /// The tension coefficient of an edge along `edge` (any length).
    pub fn coefficient(&self, edge: DVec3) -> f64 {
        match *self {
            Tension::Uniform(s) => s,
            Tension::PerAxis(s) => {
                let u = edge.normalize_or_zero();
                s.dot(u * u)
            }
        }
    }

    /// Rest length `l = d (1 − s)` of the edge between reference points `a` and `b`.
    // PHYSICS.md §2.2, eq. 3.
    pub fn rest_length(&self, a: DVec3, b: DVec3) -> f64 {
        let e = b - a;
        e.length() * (1.0 - self.coefficient(e))
    }

    /// Ok, or why the coefficients are out of `[0, 1)`.
    pub fn validate(&self) -> Result<(), String> {
        let ok = |s: f64| s.is_finite() && (0.0..1.0).contains(&s);
        match *self {
            Tension::Uniform(s) if !ok(s) => Err(format!("Uniform({s}) must lie in [0, 1)")),
            Tension::PerAxis(s) if !(ok(s.x) && ok(s.y) && ok(s.z)) => Err(format!(
                "PerAxis({}, {}, {}) components must lie in [0, 1)",
                s.x, s.y, s.z
            )),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_tension_shortens_by_s() {
        let t = Tension::Uniform(0.04);
        let l = t.rest_length(DVec3::ZERO, DVec3::new(0.0, 0.02, 0.0));
        assert!((l - 0.0192).abs() < 1e-15);
    }

    #[test]
    fn per_axis_tension_follows_the_edge_direction() {
        let t = Tension::PerAxis(DVec3::new(0.06, 0.02, 0.0));
        assert!((t.coefficient(DVec3::X) - 0.06).abs() < 1e-15);
        assert!((t.coefficient(DVec3::new(0.0, -3.0, 0.0)) - 0.02).abs() < 1e-15);
        assert!((t.coefficient(DVec3::new(1.0, 1.0, 0.0)) - 0.04).abs() < 1e-15);
        assert!(t.coefficient(DVec3::Z).abs() < 1e-15);
        assert!(
            Tension::PerAxis(DVec3::new(0.0, 1.2, 0.0))
                .validate()
                .is_err()
        );
    }
}
