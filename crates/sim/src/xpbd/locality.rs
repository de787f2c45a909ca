//! Memory in the order it is used (issue 35, item 2): the tets of each colour (and of each
//! group of the partitioned sweep) stored by their lowest node index, so that a colour's
//! pass gathers its nodes walking up the node array, whatever order the mesh listed its
//! tets in.
//!
//! Tets of one colour share no node, so the order inside a colour changes no result, to the
//! bit: the colouring itself (greedy, in mesh order) and every sum stay as they are. The
//! mesh, the node numbering and every output keep the user's numbering; only the solver's
//! slots (`Solver::slot_tets`) move. Measured (docs/performance.md, "Memory order"):
//! nothing at the default scene's 34k tets, which fit in L2; at 1.1M tets 19–22 % off a
//! sweep where the tets are listed at random, and within a few per cent of mesh order
//! where they are in node order already (every generated scene). A Morton curve through
//! the centroids instead cost 19–23 % on the generated meshes.

/// How the solver orders the tets inside each colour and group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TetOrder {
    /// By lowest node index, then mesh index (the default).
    #[default]
    Nodes,
    /// By mesh index, as before issue 35's memory order: for tests and measurement.
    Mesh,
}

impl TetOrder {
    /// The sort key of each tet inside its colour and group (all zero in mesh order, so
    /// the tet index decides).
    pub(crate) fn keys(self, tets: &[[u32; 4]]) -> Vec<u32> {
        match self {
            TetOrder::Nodes => tets
                .iter()
                .map(|t| t[0].min(t[1]).min(t[2]).min(t[3]))
                .collect(),
            TetOrder::Mesh => vec![0; tets.len()],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tet's key is its lowest node; in mesh order every key is the same.
    #[test]
    fn keys_are_the_lowest_nodes() {
        let tets = [[9, 4, 7, 5], [1, 2, 3, 0], [6, 8, 10, 11]];
        assert_eq!(TetOrder::Nodes.keys(&tets), [4, 0, 6]);
        assert_eq!(TetOrder::Mesh.keys(&tets), [0; 3]);
    }
}
