//! Laplacian smoothing of the nodes around a cut (PHYSICS.md §2.4, last step): each node
//! moves part of the way to the mean of its neighbours, in the reference and the current
//! configuration alike (so its rest lengths follow, eq. 3). Surface nodes slide within a
//! flat surface only; held axes stay held; a move that would lower the smallest dihedral
//! angle around the node, or of any tet the cut created, is refused.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::node_move::{tets_quality, try_move};
use crate::mass_spring::MassSpringModel;
use crate::mesh::TET_FACES;

/// Smooth `nodes` `iterations` times with weight `weight` (0..1); `created` are the tets the
/// cut made, whose worst angle must not drop. Returns the nodes that moved.
pub(crate) fn smooth(
    model: &mut MassSpringModel,
    nodes: &[u32],
    created: &HashSet<u32>,
    weight: f64,
    iterations: u32,
) -> Vec<u32> {
    let mut moved = Vec::new();
    for _ in 0..iterations {
        for &v in nodes {
            let vi = v as usize;
            if model.fixed_axes(vi).is_pinned() {
                continue;
            }
            let Some(d) = laplacian_step(model, v, weight) else {
                continue;
            };
            let own: Vec<u32> = model
                .tets_of(vi)
                .iter()
                .copied()
                .filter(|t| created.contains(t))
                .collect();
            let created_before = tets_quality(model, &own);
            let ok = try_move(model, v, d, |before, after| {
                after.min_deg >= before.min_deg - 1e-9
            });
            if ok && tets_quality(model, &own).min_deg < created_before.min_deg - 1e-9 {
                model.displace(vi, -d);
                continue;
            }
            if ok {
                moved.push(v);
            }
        }
    }
    moved.sort_unstable();
    moved.dedup();
    moved
}

/// The smoothing displacement of node `v`, restricted to its free axes and, on the
/// surface, to the tangent plane of a flat surface; `None` at creases and corners.
fn laplacian_step(model: &MassSpringModel, v: u32, weight: f64) -> Option<DVec3> {
    let x = model.reference_positions();
    let vi = v as usize;
    let mut nbrs: Vec<u32> = model
        .tets_of(vi)
        .iter()
        .flat_map(|&t| model.tets()[t as usize])
        .filter(|&w| w != v)
        .collect();
    nbrs.sort_unstable();
    nbrs.dedup();
    if nbrs.is_empty() {
        return None;
    }
    let mean = nbrs.iter().map(|&w| x[w as usize]).sum::<DVec3>() / nbrs.len() as f64;
    let mut d = model.fixed_axes(vi).free_part(weight * (mean - x[vi]));
    // Faces around v seen once are on the surface.
    let mut faces: HashMap<[u32; 3], (usize, DVec3)> = HashMap::new();
    for &t in model.tets_of(vi) {
        let tet = model.tets()[t as usize];
        for (f, local) in TET_FACES.iter().enumerate() {
            if tet[f] == v {
                continue;
            }
            let tri = local.map(|l| tet[l]);
            let n = (x[tri[1] as usize] - x[tri[0] as usize])
                .cross(x[tri[2] as usize] - x[tri[0] as usize]);
            let mut key = tri;
            key.sort_unstable();
            faces.entry(key).or_insert((0, n)).0 += 1;
        }
    }
    let normals: Vec<DVec3> = faces
        .values()
        .filter(|(count, _)| *count == 1)
        .filter_map(|(_, n)| n.try_normalize())
        .collect();
    if let Some(&n0) = normals.first() {
        if normals.iter().any(|n| n.dot(n0).abs() < 1.0 - 1e-9) {
            return None;
        }
        d -= n0 * d.dot(n0);
    }
    (d.length() > 0.0).then_some(d)
}
