//! Figures of a cut model for the Nakao experiments (PHYSICS.md §2.6): element counts,
//! cut-surface area, wound opening.

use std::collections::HashMap;

use glam::DVec3;
use serde::Serialize;

use crate::mass_spring::MassSpringModel;
use crate::mesh::TET_FACES;

/// Element counts as the paper reports them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MeshCounts {
    /// Nodes.
    pub nodes: usize,
    /// Edges (springs).
    pub edges: usize,
    /// Surface triangles (faces of exactly one tet).
    pub triangles: usize,
    /// Tets.
    pub tets: usize,
}

/// Counts of `model`.
pub fn counts(model: &MassSpringModel) -> MeshCounts {
    let mut faces: HashMap<[u32; 3], u8> = HashMap::with_capacity(model.tet_count() * 2);
    for tet in model.tets() {
        for f in TET_FACES {
            let mut key = f.map(|l| tet[l]);
            key.sort_unstable();
            *faces.entry(key).or_default() += 1;
        }
    }
    MeshCounts {
        nodes: model.node_count(),
        edges: model.edge_count(),
        triangles: faces.values().filter(|&&c| c == 1).count(),
        tets: model.tet_count(),
    }
}

/// Total area of the cut surfaces at the current positions, m².
pub fn cut_surface_area(model: &MassSpringModel) -> f64 {
    cut_triangles(model)
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| model.positions()[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// The cut-surface triangles (outward wound, node indices).
pub fn cut_triangles(model: &MassSpringModel) -> Vec<[u32; 3]> {
    model
        .tets()
        .iter()
        .zip(model.tet_cut_faces())
        .flat_map(|(tet, &flags)| {
            (0..4)
                .filter(move |f| flags & (1 << f) != 0)
                .map(move |f| TET_FACES[f].map(|l| tet[l]))
        })
        .collect()
}

/// Width of the wound near `centre`: the mean distance between the two copies of every
/// node the cut duplicated whose reference position lies within `radius` of `centre`;
/// `None` when there is none.
pub fn opening_width(model: &MassSpringModel, centre: DVec3, radius: f64) -> Option<f64> {
    let x = model.positions();
    let r = model.reference_positions();
    let gaps: Vec<f64> = model
        .twins()
        .iter()
        .filter(|[a, _]| (r[*a as usize] - centre).length() <= radius)
        .map(|[a, b]| (x[*a as usize] - x[*b as usize]).length())
        .collect();
    (!gaps.is_empty()).then(|| gaps.iter().sum::<f64>() / gaps.len() as f64)
}
