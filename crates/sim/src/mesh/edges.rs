//! The unique edges of a tet mesh with rest lengths and node→edge adjacency: the shared
//! structure of the edge-based models (mass-spring, PHYSICS.md §2.1; three-element
//! rheology, §3).

use glam::Vec3;

use super::{TET_EDGES, TetMesh};

/// Unique undirected edges of a tet mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeList {
    /// Edges as (lower, higher) node index pairs, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Rest length of each edge (distance between rest positions), m.
    pub rest_length: Vec<f32>,
    /// CSR offsets into [`EdgeList::node_edge_list`] per node.
    pub node_edge_offsets: Vec<u32>,
    /// Edges incident to each node (CSR payload).
    pub node_edge_list: Vec<u32>,
}

impl EdgeList {
    /// All unique edges of `mesh`'s tets, measured at the rest positions.
    pub fn of_mesh(mesh: &TetMesh) -> Self {
        Self::from_tets(mesh.node_count(), &mesh.tets, &mesh.rest_positions)
    }

    /// All unique edges of `tets` over `node_count` nodes at `positions`.
    pub fn from_tets(node_count: usize, tets: &[[u32; 4]], positions: &[Vec3]) -> Self {
        let mut edges: Vec<[u32; 2]> = tets
            .iter()
            .flat_map(|t| {
                TET_EDGES.iter().map(move |&(a, b)| {
                    let (i, j) = (t[a], t[b]);
                    [i.min(j), i.max(j)]
                })
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let rest_length = edges
            .iter()
            .map(|e| (positions[e[0] as usize] - positions[e[1] as usize]).length())
            .collect();
        let mut offsets = vec![0u32; node_count + 1];
        for e in &edges {
            offsets[e[0] as usize + 1] += 1;
            offsets[e[1] as usize + 1] += 1;
        }
        for i in 0..node_count {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut list = vec![0u32; edges.len() * 2];
        for (k, e) in edges.iter().enumerate() {
            for &n in e {
                list[fill[n as usize] as usize] = k as u32;
                fill[n as usize] += 1;
            }
        }
        EdgeList {
            edges,
            rest_length,
            node_edge_offsets: offsets,
            node_edge_list: list,
        }
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// Whether there are no edges.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Edges incident to node `i`.
    pub fn edges_of_node(&self, i: usize) -> &[u32] {
        let a = self.node_edge_offsets[i] as usize;
        let b = self.node_edge_offsets[i + 1] as usize;
        &self.node_edge_list[a..b]
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;

    #[test]
    fn two_tets_sharing_a_face_have_nine_edges() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];
        let e = EdgeList::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]], &p);
        assert_eq!(e.len(), 9);
        assert_eq!(e.edges_of_node(0).len(), 3);
        assert_eq!(e.edges_of_node(1).len(), 4);
        assert!((e.rest_length[0] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn plate_edge_count_matches_euler_characteristic() {
        // For a tet mesh of a ball: V − E + F − T = 1.
        let (mesh, _) =
            TetMesh::from_raw(block(Vec3::ZERO, Vec3::ONE, UVec3::new(3, 2, 2))).unwrap();
        let e = EdgeList::of_mesh(&mesh);
        let faces = (4 * mesh.tet_count() + mesh.boundary.len()) / 2;
        let chi =
            mesh.node_count() as i64 - e.len() as i64 + faces as i64 - mesh.tet_count() as i64;
        assert_eq!(chi, 1);
    }
}
