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
    cut_faces(model).map(|(_, face)| face).collect()
}

/// Every tet face the cutter opened: its tet's index and its corners (outward wound,
/// node indices).
pub fn cut_faces(model: &MassSpringModel) -> impl Iterator<Item = (usize, [u32; 3])> + '_ {
    model
        .tets()
        .iter()
        .zip(model.tet_cut_faces())
        .enumerate()
        .flat_map(|(t, (tet, &flags))| {
            (0..4)
                .filter(move |f| flags & (1 << f) != 0)
                .map(move |f| (t, TET_FACES[f].map(|l| tet[l])))
        })
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

/// Aspect-ratio quality of the tet with corners `p`: the radius ratio `3 r_in / R_circ`,
/// 1 for a regular tet, towards 0 for slivers and needles (0 for a flat one).
pub fn radius_ratio(p: [DVec3; 4]) -> f64 {
    let (a, b, c) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let six_v = a.dot(b.cross(c)).abs();
    if six_v <= 0.0 {
        return 0.0;
    }
    let area = |x: DVec3, y: DVec3, z: DVec3| 0.5 * (y - x).cross(z - x).length();
    let faces = area(p[1], p[2], p[3])
        + area(p[0], p[2], p[3])
        + area(p[0], p[1], p[3])
        + area(p[0], p[1], p[2]);
    let r_in = 0.5 * six_v / faces;
    let num = b.cross(c) * a.length_squared()
        + c.cross(a) * b.length_squared()
        + a.cross(b) * c.length_squared();
    let r_circ = num.length() / (2.0 * six_v);
    (3.0 * r_in / r_circ).min(1.0)
}

/// The smallest radius ratio over the tets that hold a node numbered `first_new` or more
/// (the tets a cut created), in the reference configuration; `None` when there is none.
pub fn worst_new_tet_quality(model: &MassSpringModel, first_new: usize) -> Option<f64> {
    let x = model.reference_positions();
    model
        .tets()
        .iter()
        .filter(|t| t.iter().any(|&v| v as usize >= first_new))
        .map(|t| radius_ratio(t.map(|v| x[v as usize])))
        .min_by(f64::total_cmp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_ratio_is_one_for_a_regular_tet_and_small_for_a_sliver() {
        let s = 1.0 / 2f64.sqrt();
        let regular = [
            DVec3::new(1.0, 0.0, -s),
            DVec3::new(-1.0, 0.0, -s),
            DVec3::new(0.0, 1.0, s),
            DVec3::new(0.0, -1.0, s),
        ];
        assert!((radius_ratio(regular) - 1.0).abs() < 1e-12);
        let sliver = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.01), DVec3::Y];
        assert!(radius_ratio(sliver) < 0.05, "{}", radius_ratio(sliver));
        assert_eq!(
            radius_ratio([DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::X]),
            0.0
        );
    }
}
