//! Connectivity queries over (a subset of) a tet mesh.

use super::TetMesh;

/// Number of connected components among the tets for which `live(t)` is true, where two
/// tets are connected when they share a node (a shared node transmits force in the solver).
pub fn connected_components(mesh: &TetMesh, live: impl Fn(usize) -> bool) -> usize {
    component_labels(mesh, live).1
}

/// Per-tet component label (`u32::MAX` for tets that are not live) and the component count.
pub fn component_labels(mesh: &TetMesh, live: impl Fn(usize) -> bool) -> (Vec<u32>, usize) {
    let n = mesh.node_count();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    for (t, tet) in mesh.tets.iter().enumerate() {
        if !live(t) {
            continue;
        }
        let r0 = find(&mut parent, tet[0]);
        for &v in &tet[1..] {
            let r = find(&mut parent, v);
            if r != r0 {
                parent[r as usize] = r0;
            }
        }
    }
    let mut label_of_root = vec![u32::MAX; n];
    let mut labels = vec![u32::MAX; mesh.tet_count()];
    let mut count = 0u32;
    for (t, tet) in mesh.tets.iter().enumerate() {
        if !live(t) {
            continue;
        }
        let r = find(&mut parent, tet[0]) as usize;
        if label_of_root[r] == u32::MAX {
            label_of_root[r] = count;
            count += 1;
        }
        labels[t] = label_of_root[r];
    }
    (labels, count as usize)
}
