//! The pieces of the body a coarse corner covers: the free nodes it weights, connected
//! through the edges of the live tets. A corner whose cubes hold both sides of a cut
//! covers two pieces, and each becomes its own coarse node, so the coarse level never ties
//! the sides of a cut together (the coarse nodes duplicated per connected piece of a cell,
//! as in Dick, Georgii & Westermann 2011, "A hexahedral multigrid approach for simulating
//! cuts in deformable objects"; docs/physics-notes.md, "The coarse level after a cut").

use super::rest_tet::RestTet;
use crate::mesh::disjoint_sets::DisjointSets;

/// A fine node's coarse corners and their weights (all zero for a node that is not free).
pub type NodeWeights = [(u32, f32); 8];

/// The pieces of every corner and the fragments of the body.
pub struct Pieces {
    /// Per weight slot `8 i + k` (node `i`'s corner `k`), the first slot of its piece: the
    /// slots of one corner joined by a live tet's edge whose two nodes both weight it. A
    /// slot with no weight is its own piece.
    pub slot: Vec<u32>,
    /// Per node, the first node of its fragment: the nodes the live tets connect. A piece
    /// lies in one fragment.
    pub fragment: Vec<u32>,
}

/// The pieces of the corners in `weights` and the fragments the tets marked `live` leave.
pub fn pieces(weights: &[NodeWeights], tets: &[RestTet], live: &[bool]) -> Pieces {
    let mut slots = DisjointSets::new(8 * weights.len());
    let mut nodes = DisjointSets::new(weights.len());
    for (tet, _) in tets.iter().zip(live).filter(|(_, l)| **l) {
        for (e, &a) in tet.nodes.iter().enumerate() {
            nodes.join(a as usize, tet.nodes[(e + 1) % 4] as usize);
            for &b in &tet.nodes[e + 1..] {
                join_shared_corners(&mut slots, weights, a as usize, b as usize);
            }
        }
    }
    Pieces {
        slot: slots.first_members(),
        fragment: nodes.first_members(),
    }
}

/// Join node `a`'s and node `b`'s slots of every corner both weight.
fn join_shared_corners(sets: &mut DisjointSets, weights: &[NodeWeights], a: usize, b: usize) {
    for (ka, &(id, wa)) in weights[a].iter().enumerate() {
        if wa <= 0.0 {
            continue;
        }
        // Nodes of one cube list its corners in the same order.
        let same = weights[b][ka].0 == id && weights[b][ka].1 > 0.0;
        let shared = if same {
            Some(ka)
        } else {
            weights[b].iter().position(|&(j, wb)| j == id && wb > 0.0)
        };
        if let Some(kb) = shared {
            sets.join(8 * a + ka, 8 * b + kb);
        }
    }
}
