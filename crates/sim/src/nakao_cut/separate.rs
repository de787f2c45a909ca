//! Remodelling (PHYSICS.md §2.3, Fig. 2): open the mesh along the cut faces by giving each
//! side its own copy of every node on them. Springs that crossed the cut disappear with the
//! shared tets; each copy's mass follows from its own tets (eq. 4).

use std::collections::{HashMap, HashSet};

use crate::mass_spring::MassSpringModel;
use crate::mesh::TET_FACES;
use crate::mesh::disjoint_sets::DisjointSets;

/// What the separation did.
#[derive(Debug, Clone, Default)]
pub(crate) struct Separation {
    /// (node, copy) for every duplication.
    pub duplicated: Vec<[u32; 2]>,
    /// Interior faces opened (each now two boundary faces).
    pub opened_faces: usize,
    /// Tet faces newly flagged as cut surface (a face opened by an earlier advance is
    /// counted in `opened_faces` again, not here).
    pub flagged_faces: usize,
    /// Tets whose nodes were renumbered.
    pub touched_tets: Vec<u32>,
}

/// Open every interior face of `tets` whose three nodes satisfy `on_cut`, duplicating the nodes whose tet star the opened faces
/// split into several face-connected parts. A node where the cut ends (its star still
/// connected around the cut's edge) is not duplicated: the cut's front stays attached.
pub(crate) fn separate(
    model: &mut MassSpringModel,
    tets: &[u32],
    on_cut: impl Fn(u32) -> bool,
) -> Separation {
    let mut faces: HashMap<[u32; 3], Vec<(u32, u8)>> = HashMap::new();
    for &t in tets {
        let tet = model.tets[t as usize];
        for (f, local) in TET_FACES.iter().enumerate() {
            let nodes = local.map(|l| tet[l]);
            if nodes.iter().all(|&v| on_cut(v)) {
                let mut key = nodes;
                key.sort_unstable();
                faces.entry(key).or_default().push((t, f as u8));
            }
        }
    }
    let mut marked: HashSet<(u32, u8)> = HashSet::new();
    let mut cut_nodes: Vec<u32> = Vec::new();
    let mut out = Separation::default();
    for (key, sides) in &faces {
        if sides.len() == 2 {
            marked.extend(sides.iter().copied());
            cut_nodes.extend_from_slice(key);
            out.opened_faces += 1;
        }
    }
    cut_nodes.sort_unstable();
    cut_nodes.dedup();
    for &(t, f) in &marked {
        let flags = model.tet_cut_faces[t as usize];
        model.tet_cut_faces[t as usize] = flags | 1 << f;
        out.flagged_faces += usize::from(flags & 1 << f == 0);
    }
    for v in cut_nodes {
        let components = star_components(model, v, &marked);
        for part in components.iter().skip(1) {
            let vi = v as usize;
            let copy = model.add_node(
                model.reference[vi],
                model.positions[vi],
                model.velocities[vi],
                model.fixed[vi],
            );
            for &t in part {
                let mut tet = model.tets[t as usize];
                for x in tet.iter_mut().filter(|x| **x == v) {
                    *x = copy;
                }
                model.set_tet(t, tet);
                out.touched_tets.push(t);
            }
            out.duplicated.push([v, copy]);
        }
    }
    out.touched_tets.sort_unstable();
    out.touched_tets.dedup();
    out
}

/// The tets around `v` grouped into parts connected through faces that contain `v` and are
/// not `marked`; parts ordered by their lowest tet index.
fn star_components(model: &MassSpringModel, v: u32, marked: &HashSet<(u32, u8)>) -> Vec<Vec<u32>> {
    let star: Vec<u32> = model.node_tets[v as usize].clone();
    let mut sets = DisjointSets::new(star.len());
    let mut seen: HashMap<[u32; 2], usize> = HashMap::new();
    for (s, &t) in star.iter().enumerate() {
        let tet = model.tets[t as usize];
        for (f, local) in TET_FACES.iter().enumerate() {
            if tet[f] == v || marked.contains(&(t, f as u8)) {
                continue;
            }
            let mut key = [0u32; 2];
            let mut k = 0;
            for &l in local {
                if tet[l] != v {
                    key[k.min(1)] = tet[l];
                    k += 1;
                }
            }
            key.sort_unstable();
            match seen.get(&key) {
                Some(&other) => sets.join(s, other),
                None => {
                    seen.insert(key, s);
                }
            }
        }
    }
    let mut groups: HashMap<usize, Vec<u32>> = HashMap::new();
    for (s, &t) in star.iter().enumerate() {
        let r = sets.find(s);
        groups.entry(r).or_default().push(t);
    }
    let mut parts: Vec<Vec<u32>> = groups.into_values().collect();
    for p in &mut parts {
        p.sort_unstable();
    }
    parts.sort_by_key(|p| p[0]);
    parts
}
