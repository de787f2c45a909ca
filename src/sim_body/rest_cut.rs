//! What a body has cut, in rest (material) coordinates, for scoring an exercise
//! (docs/scoring.md): the tets an XPBD body released, or the cut surface the Nakao cutter
//! opened by remodelling.

use glam::DVec3;
use incise_sim::mass_spring::MassSpringModel;
use incise_sim::nakao_cut::measure::cut_faces;

/// A body's cut at rest.
#[derive(Debug, Clone, PartialEq)]
pub enum RestCut {
    /// Per tet of the scene's mesh, whether the XPBD body released it.
    Released(Vec<bool>),
    /// The faces of the cut surface (both sides of the wound), at rest.
    Faces(Vec<RestCutFace>),
}

impl RestCut {
    /// The tets an XPBD `solver` has released (its cut's live flags, negated).
    pub fn released_of(solver: &incise_sim::Solver) -> RestCut {
        RestCut::Released(solver.cut().live().iter().map(|l| !l).collect())
    }
}

/// One face of a cut surface at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestCutFace {
    /// Its corners at their reference positions, m.
    pub corners: [DVec3; 3],
    /// The tet it bounds (an index into the cut model's tets).
    pub tet: u32,
    /// That tet's reference volume, m³.
    pub tet_volume: f64,
}

impl RestCutFace {
    /// The face's centroid, m.
    pub fn centroid(&self) -> DVec3 {
        (self.corners[0] + self.corners[1] + self.corners[2]) / 3.0
    }
}

/// The cut surface of a Nakao model: every tet face the cutter opened, at the reference
/// positions (new nodes at their interpolated ones, PHYSICS.md §2.4).
pub fn cut_faces_at_rest(model: &MassSpringModel) -> RestCut {
    let x = model.reference_positions();
    let faces = cut_faces(model)
        .map(|(t, face)| RestCutFace {
            corners: face.map(|i| x[i as usize]),
            tet: t as u32,
            tet_volume: model.reference_volume(t),
        })
        .collect();
    RestCut::Faces(faces)
}
