//! Connectivity queries over (a subset of) a tet mesh.

use super::TetMesh;
use super::disjoint_sets::DisjointSets;

/// Number of connected components among the tets for which `live(t)` is true, where two
/// tets are connected when they share a node (a shared node transmits force in the solver).
pub fn connected_components(mesh: &TetMesh, live: impl Fn(usize) -> bool) -> usize {
    component_labels(mesh, live).1
}

/// Per-tet component label (`u32::MAX` for tets that are not live) and the component count.
pub fn component_labels(mesh: &TetMesh, live: impl Fn(usize) -> bool) -> (Vec<u32>, usize) {
    let n = mesh.node_count();
    let mut sets = DisjointSets::new(n);
    for (t, tet) in mesh.tets.iter().enumerate() {
        if !live(t) {
            continue;
        }
        for &v in &tet[1..] {
            sets.join(tet[0] as usize, v as usize);
        }
    }
    let mut label_of_root = vec![u32::MAX; n];
    let mut labels = vec![u32::MAX; mesh.tet_count()];
    let mut count = 0u32;
    for (t, tet) in mesh.tets.iter().enumerate() {
        if !live(t) {
            continue;
        }
        let r = sets.find(tet[0] as usize);
        if label_of_root[r] == u32::MAX {
            label_of_root[r] = count;
            count += 1;
        }
        labels[t] = label_of_root[r];
    }
    (labels, count as usize)
}
