//! The indexed element structure of PHYSICS.md §2.5: unique vertices, edges, triangles and
//! tets, and for every vertex its neighbours and the edges, triangles and tets it belongs to.

use std::collections::HashMap;

use super::MassSpringModel;
use crate::mesh::{TET_EDGES, TET_FACES};

/// Compressed rows: `offsets[i]..offsets[i + 1]` indexes `items` for row `i`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Rows {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Rows {
    pub(crate) fn build(rows: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Rows {
        let mut offsets = vec![0u32; rows + 1];
        for (r, _) in pairs.clone() {
            offsets[r as usize + 1] += 1;
        }
        for i in 0..rows {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[rows] as usize];
        for (r, item) in pairs {
            items[fill[r as usize] as usize] = item;
            fill[r as usize] += 1;
        }
        Rows { offsets, items }
    }

    /// The items of row `i`.
    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

/// Indexed vertices, edges, triangles and tets with vertex adjacency (PHYSICS.md §2.5).
#[derive(Debug, Clone, Default)]
pub struct ElementIndex {
    /// Unique edges (lower, higher node).
    pub edges: Vec<[u32; 2]>,
    /// Unique triangles (sorted nodes), interior and surface.
    pub triangles: Vec<[u32; 3]>,
    /// How many tets use each triangle (1: surface).
    pub triangle_uses: Vec<u8>,
    /// Per vertex: neighbouring vertices.
    pub vertex_neighbours: Rows,
    /// Per vertex: edges it belongs to.
    pub vertex_edges: Rows,
    /// Per vertex: triangles it belongs to.
    pub vertex_triangles: Rows,
    /// Per vertex: tets it belongs to.
    pub vertex_tets: Rows,
}

impl ElementIndex {
    /// Index the elements of `model`.
    pub fn build(model: &MassSpringModel) -> ElementIndex {
        let n = model.node_count();
        let tets = model.tets();
        let mut edge_id: HashMap<[u32; 2], u32> = HashMap::with_capacity(tets.len() * 2);
        let mut tri_id: HashMap<[u32; 3], u32> = HashMap::with_capacity(tets.len() * 2);
        let mut out = ElementIndex::default();
        for tet in tets {
            for (a, b) in TET_EDGES {
                let key = [tet[a].min(tet[b]), tet[a].max(tet[b])];
                edge_id.entry(key).or_insert_with(|| {
                    out.edges.push(key);
                    (out.edges.len() - 1) as u32
                });
            }
            for f in TET_FACES {
                let mut key = f.map(|l| tet[l]);
                key.sort_unstable();
                let id = *tri_id.entry(key).or_insert_with(|| {
                    out.triangles.push(key);
                    out.triangle_uses.push(0);
                    (out.triangles.len() - 1) as u32
                });
                out.triangle_uses[id as usize] += 1;
            }
        }
        let edges = &out.edges;
        out.vertex_edges = Rows::build(
            n,
            edges
                .iter()
                .enumerate()
                .flat_map(|(k, e)| [(e[0], k as u32), (e[1], k as u32)]),
        );
        out.vertex_neighbours =
            Rows::build(n, edges.iter().flat_map(|e| [(e[0], e[1]), (e[1], e[0])]));
        out.vertex_triangles = Rows::build(
            n,
            out.triangles
                .iter()
                .enumerate()
                .flat_map(|(k, t)| t.map(|v| (v, k as u32))),
        );
        out.vertex_tets = Rows::build(
            n,
            tets.iter()
                .enumerate()
                .flat_map(|(k, t)| t.map(|v| (v, k as u32))),
        );
        out
    }

    /// Number of surface triangles (used by one tet).
    pub fn surface_triangles(&self) -> usize {
        self.triangle_uses.iter().filter(|&&u| u == 1).count()
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::{block, plate};
    use crate::mass_spring::MassSpringParams;
    use crate::mesh::TetMesh;

    #[test]
    fn plate_index_matches_the_documented_counts() {
        let (mesh, _) = TetMesh::from_raw(plate()).unwrap();
        let m = MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap();
        let idx = ElementIndex::build(&m);
        assert_eq!(idx.edges.len(), 5_953);
        assert_eq!(idx.surface_triangles(), 2_496);
        assert_eq!(idx.vertex_tets.row(0), m.tets_of(0));
    }

    #[test]
    fn every_vertex_row_is_consistent() {
        let (mesh, _) =
            TetMesh::from_raw(block(Vec3::ZERO, Vec3::ONE, UVec3::new(2, 2, 2))).unwrap();
        let m = MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap();
        let idx = ElementIndex::build(&m);
        for v in 0..m.node_count() {
            assert_eq!(idx.vertex_neighbours.row(v).len(), m.springs_of(v).len());
            for &e in idx.vertex_edges.row(v) {
                assert!(idx.edges[e as usize].contains(&(v as u32)));
            }
            for &t in idx.vertex_triangles.row(v) {
                assert!(idx.triangles[t as usize].contains(&(v as u32)));
            }
        }
        // Euler characteristic of a ball: V − E + F − T = 1.
        let chi = m.node_count() as i64 - idx.edges.len() as i64 + idx.triangles.len() as i64
            - m.tet_count() as i64;
        assert_eq!(chi, 1);
    }
}
