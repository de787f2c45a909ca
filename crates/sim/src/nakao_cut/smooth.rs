//! Laplacian smoothing of the nodes around a cut (PHYSICS.md §2.4, last step): each node
//! moves part of the way to the mean of its neighbours, in the reference and the current
//! configuration alike (so its rest lengths follow, eq. 3). Surface nodes slide within a
//! flat surface only; held axes stay held; a move that would lower the smallest dihedral
//! angle around the node, or of any tet the cut created, is refused.

use std::collections::HashSet;

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
    // Faces around v seen once are on the surface, in the order of their sorted nodes: the
    // first normal is the one the move is projected on, and normals parallel to 1e-9 may
    // differ in their last bits, so the order must not be a hash map's (it differs per map).
    let mut faces: Vec<([u32; 3], DVec3)> = Vec::new();
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
            faces.push((key, n));
        }
    }
    faces.sort_by_key(|(key, _)| *key);
    let normals: Vec<DVec3> = faces
        .chunk_by(|a, b| a.0 == b.0)
        .filter(|same| same.len() == 1)
        .filter_map(|same| same[0].1.try_normalize())
        .collect();
    if let Some(&n0) = normals.first() {
        if normals.iter().any(|n| n.dot(n0).abs() < 1.0 - 1e-9) {
            return None;
        }
        d -= n0 * d.dot(n0);
    }
    (d.length() > 0.0).then_some(d)
}

#[cfg(test)]
mod tests {
    use glam::{Quat, UVec3, Vec3};

    use super::*;
    use crate::generate::block;
    use crate::mass_spring::MassSpringParams;
    use crate::mesh::TetMesh;

    /// A smoothing step of a node on a flat but tilted surface (its face normals parallel
    /// to 1e-9 but not bit for bit) projects on the same normal every time: the same bits
    /// call after call (a hash map's order, new with every map, decided it before).
    #[test]
    fn a_surface_step_is_the_same_bits_every_call() {
        let mut raw = block(Vec3::ZERO, Vec3::new(0.03, 0.03, 0.01), UVec3::new(6, 6, 2));
        let turn = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        raw.positions.iter_mut().for_each(|p| *p = turn * *p);
        let (mesh, _) = TetMesh::from_raw(raw).unwrap();
        let model = MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap();
        let bits = |d: Option<DVec3>| d.map(|d| d.to_array().map(f64::to_bits));
        let mut projected = 0;
        for v in 0..model.node_count() as u32 {
            let first = bits(laplacian_step(&model, v, 0.5));
            projected += usize::from(first.is_some());
            for _ in 0..20 {
                assert_eq!(bits(laplacian_step(&model, v, 0.5)), first, "node {v}");
            }
        }
        assert!(projected > 0);
    }
}
