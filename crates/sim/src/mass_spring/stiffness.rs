//! How each spring's constant follows from the mesh (PHYSICS.md §2.1, and the Nakao
//! section of docs/physics-notes.md for why the default departs from the paper).

use serde::{Deserialize, Serialize};

/// The law that gives every edge its spring constant.
///
/// Nakao 2003 gives every edge the same `k` (`Uniform`). A cut then splits an edge into two
/// halves of `k` each, in series `k/2`, and adds new edges of `k`: the subdivided region is
/// no longer as stiff, nor as tense, as the uncut one. `TetVolume` derives each constant
/// from the geometry instead, so a split keeps both.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum StiffnessLaw {
    /// The paper's form: every edge has the constant `k` of the parameters.
    Uniform,
    /// `k_e = c · W_e / d_e²`, with `W_e` the summed reference volume of the tets around
    /// edge e and `d_e` its reference length (Van Gelder 1998's volume-weighted springs);
    /// `c` is set once, on the uncut mesh, so that its mean edge constant is `k`.
    #[default]
    TetVolume,
}

impl StiffnessLaw {
    /// The spring constant of an edge of reference length `length` whose tets have summed
    /// reference volume `volume`; `k` for `Uniform`, `scale · volume / length²` otherwise.
    // PHYSICS.md §2.1 (k of eq. 1); the TetVolume form is ours (docs/physics-notes.md).
    pub fn constant(&self, k: f64, scale: f64, volume: f64, length: f64) -> f64 {
        match self {
            StiffnessLaw::Uniform => k,
            StiffnessLaw::TetVolume if length > 0.0 => scale * volume / (length * length),
            StiffnessLaw::TetVolume => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_halved_edge_in_series_is_the_parent_edge() {
        // Halving an edge halves its length and the volume of each tet around it: each half
        // is 2 k_e, the pair in series k_e, and the pre-tension k_e s d is unchanged.
        let law = StiffnessLaw::TetVolume;
        let whole = law.constant(100.0, 3.0, 6.0e-9, 0.01);
        let half = law.constant(100.0, 3.0, 3.0e-9, 0.005);
        assert!((half - 2.0 * whole).abs() < 1e-12 * whole);
        assert_eq!(
            StiffnessLaw::Uniform.constant(100.0, 3.0, 3.0e-9, 0.005),
            100.0
        );
    }
}
