//! The topology invariants every cut must keep: no dangling indices, no flat or inverted
//! tet, mass conserved, faces and edges shared consistently.

use std::collections::{HashMap, HashSet};

use crate::mass_spring::MassSpringModel;
use crate::mesh::{TET_EDGES, TET_FACES};

/// Relative tolerance of the mass checks.
pub const MASS_REL_TOL: f64 = 1e-9;

/// The first invariant a model breaks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TopologyError {
    /// A tet names a node that does not exist or names one node twice.
    #[error("tet {tet} has bad node indices {nodes:?} ({count} nodes)")]
    BadTetNodes {
        /// Tet index.
        tet: usize,
        /// Its nodes.
        nodes: [u32; 4],
        /// Node count.
        count: usize,
    },
    /// A tet's reference volume is not positive.
    #[error("tet {tet} has reference volume {volume:e} m^3")]
    FlatTet {
        /// Tet index.
        tet: usize,
        /// Signed volume.
        volume: f64,
    },
    /// Node→tet adjacency disagrees with the tets.
    #[error("node {node}: adjacency lists {listed} tets but {actual} tets use it")]
    Adjacency {
        /// Node index.
        node: usize,
        /// Tets listed for it.
        listed: usize,
        /// Tets that name it.
        actual: usize,
    },
    /// A node belongs to no tet.
    #[error("node {node} belongs to no tet")]
    DanglingNode {
        /// Node index.
        node: usize,
    },
    /// A face is used by more than two tets or twice with the same orientation.
    #[error("face {face:?} is shared inconsistently ({uses} uses)")]
    Face {
        /// Sorted node triple.
        face: [u32; 3],
        /// How many tets use it.
        uses: usize,
    },
    /// The springs are not exactly the tet edges, or not symmetric.
    #[error("springs: {0}")]
    Springs(String),
    /// Mass is not conserved, or a node's mass disagrees with eq. 4.
    #[error("mass: {0}")]
    Mass(String),
}

/// Check every invariant of `model`.
pub fn check(model: &MassSpringModel) -> Result<(), TopologyError> {
    let n = model.node_count();
    let tets = model.tets();
    let mut uses = vec![0usize; n];
    for (t, tet) in tets.iter().enumerate() {
        let bad = tet.iter().any(|&v| v as usize >= n)
            || (0..4).any(|i| (i + 1..4).any(|j| tet[i] == tet[j]));
        if bad {
            return Err(TopologyError::BadTetNodes {
                tet: t,
                nodes: *tet,
                count: n,
            });
        }
        let volume = model.reference_volume(t);
        if volume.is_nan() || volume <= 0.0 {
            return Err(TopologyError::FlatTet { tet: t, volume });
        }
        for &v in tet {
            uses[v as usize] += 1;
        }
    }
    for (v, &u) in uses.iter().enumerate() {
        let listed = model.tets_of(v);
        let consistent = listed.len() == u
            && listed
                .iter()
                .all(|&t| (t as usize) < tets.len() && tets[t as usize].contains(&(v as u32)));
        if !consistent {
            return Err(TopologyError::Adjacency {
                node: v,
                listed: listed.len(),
                actual: u,
            });
        }
        if u == 0 {
            return Err(TopologyError::DanglingNode { node: v });
        }
    }
    check_faces(tets)?;
    check_springs(model)?;
    check_mass(model)
}

fn check_faces(tets: &[[u32; 4]]) -> Result<(), TopologyError> {
    let mut faces: HashMap<[u32; 3], Vec<[u32; 3]>> = HashMap::with_capacity(tets.len() * 2);
    for tet in tets {
        for f in TET_FACES {
            let wound = f.map(|l| tet[l]);
            let mut key = wound;
            key.sort_unstable();
            faces.entry(key).or_default().push(wound);
        }
    }
    for (key, list) in faces {
        let opposite = list.len() == 2 && same_cycle(list[0], [list[1][0], list[1][2], list[1][1]]);
        if list.len() > 2 || (list.len() == 2 && !opposite) {
            return Err(TopologyError::Face {
                face: key,
                uses: list.len(),
            });
        }
    }
    Ok(())
}

/// Whether two triangles list the same nodes in the same cyclic order.
fn same_cycle(a: [u32; 3], b: [u32; 3]) -> bool {
    (0..3).any(|r| (0..3).all(|i| a[i] == b[(i + r) % 3]))
}

fn check_springs(model: &MassSpringModel) -> Result<(), TopologyError> {
    let mut edges: HashSet<(u32, u32)> = HashSet::new();
    for tet in model.tets() {
        for (a, b) in TET_EDGES {
            edges.insert((tet[a].min(tet[b]), tet[a].max(tet[b])));
        }
    }
    let x = model.reference_positions();
    let tension = model.params().tension;
    let mut count = 0usize;
    for i in 0..model.node_count() {
        for s in model.springs_of(i) {
            let j = s.node as usize;
            let key = ((i.min(j)) as u32, (i.max(j)) as u32);
            if !edges.contains(&key) {
                return Err(TopologyError::Springs(format!(
                    "spring {i}-{j} is not an edge of any tet"
                )));
            }
            if !model
                .springs_of(j)
                .iter()
                .any(|b| b.node as usize == i && b.rest == s.rest && b.stiffness == s.stiffness)
            {
                return Err(TopologyError::Springs(format!(
                    "spring {i}-{j} is not mirrored with the same rest length and constant"
                )));
            }
            let expected = tension.rest_length(x[i.min(j)], x[i.max(j)]);
            if (s.rest - expected).abs() > 1e-9 * expected.max(1e-12) {
                return Err(TopologyError::Springs(format!(
                    "spring {i}-{j} has rest length {} instead of {expected} (eq. 3)",
                    s.rest
                )));
            }
            count += 1;
        }
    }
    if count != 2 * edges.len() {
        return Err(TopologyError::Springs(format!(
            "{} spring ends for {} tet edges",
            count,
            edges.len()
        )));
    }
    Ok(())
}

fn check_mass(model: &MassSpringModel) -> Result<(), TopologyError> {
    let m0 = model.initial_mass();
    let tets: f64 = model.tet_masses().iter().sum();
    let nodes = model.total_mass();
    for (what, m) in [("tets", tets), ("nodes", nodes)] {
        if (m - m0).abs() > MASS_REL_TOL * m0 {
            return Err(TopologyError::Mass(format!(
                "{what} carry {m} kg, the model started with {m0} kg"
            )));
        }
    }
    for i in 0..model.node_count() {
        let expected: f64 = model
            .tets_of(i)
            .iter()
            .map(|&t| 0.25 * model.tet_masses()[t as usize])
            .sum();
        let m = model.masses()[i];
        if (m - expected).abs() > 1e-12 * expected.max(f64::MIN_POSITIVE) || m <= 0.0 {
            return Err(TopologyError::Mass(format!(
                "node {i} has mass {m} kg, its tets give {expected} kg (eq. 4)"
            )));
        }
    }
    Ok(())
}
