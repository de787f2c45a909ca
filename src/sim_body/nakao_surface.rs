//! What a Nakao body shows: its surface triangles (faces of exactly one tet), the spring
//! tension at each node for the heat map, and the largest node displacement.

use std::collections::HashMap;

use glam::DVec3;
use incise_sim::mass_spring::MassSpringModel;
use incise_sim::mesh::TET_FACES;

/// The faces of exactly one tet that are not cut faces (outward wound, node indices).
pub fn surface_triangles(model: &MassSpringModel) -> Vec<[u32; 3]> {
    let mut faces: HashMap<[u32; 3], ([u32; 3], u32)> = HashMap::new();
    for (tet, &cut) in model.tets().iter().zip(model.tet_cut_faces()) {
        for (f, local) in TET_FACES.iter().enumerate() {
            let tri = local.map(|l| tet[l]);
            let mut key = tri;
            key.sort_unstable();
            let entry = faces.entry(key).or_insert((tri, 0));
            entry.1 += if cut & (1 << f) != 0 { 2 } else { 1 };
        }
    }
    let mut out: Vec<[u32; 3]> = faces
        .into_values()
        .filter(|(_, n)| *n == 1)
        .map(|(tri, _)| tri)
        .collect();
    out.sort_unstable();
    out
}

/// The mean spring tension `k (l − l0)` over each node's springs, N (PHYSICS.md §2.1,
/// eq. 1; positive: stretched). A node without springs gets 0.
pub fn tension_at_nodes(model: &MassSpringModel) -> Vec<f32> {
    let x = model.positions();
    (0..model.node_count())
        .map(|i| {
            let springs = model.springs_of(i);
            let sum: f64 = springs
                .iter()
                .map(|s| s.stiffness * ((x[s.node as usize] - x[i]).length() - s.rest))
                .sum();
            if springs.is_empty() {
                0.0
            } else {
                (sum / springs.len() as f64) as f32
            }
        })
        .collect()
}

/// Largest distance of a node from its reference position, m.
pub fn max_displacement(reference: &[DVec3], x: &[DVec3]) -> f64 {
    reference
        .iter()
        .zip(x)
        .map(|(r, p)| (*p - *r).length())
        .fold(0.0, f64::max)
}
