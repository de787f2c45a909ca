//! Tetrahedral meshes: raw input from readers, and the validated `TetMesh` with rest data
//! (PHYSICS.md §1.1), adjacency and boundary faces.

mod build;
mod closest_point;
pub(crate) mod disjoint_sets;
mod edges;
pub mod quality;
mod surface;
pub mod topology;

pub use build::{DEGENERATE_REL, MeshBuildReport};
pub use closest_point::closest_point_on_triangle;
pub use edges::EdgeList;
pub use surface::TriSurface;

use glam::{Mat3, Vec3};

/// Local vertex indices of the four faces of a positively oriented tet; face `f` is
/// opposite vertex `f` and is wound so that its normal points out of the tet.
pub const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// Marker for "no neighbour" in [`TetMesh::face_neighbors`].
pub const NO_NEIGHBOR: u32 = u32::MAX;

/// A mesh as a reader produced it: node coordinates and tet connectivity, unvalidated.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    /// Node coordinates, in the file's units (see the scene's `units`).
    pub positions: Vec<Vec3>,
    /// Tets as 0-based node indices.
    pub tets: Vec<[u32; 4]>,
    /// Non-fatal remarks from the reader (e.g. skipped element types), one per line.
    pub warnings: Vec<String>,
    /// Boundary triangles given by the file (TetGen `.face`), 0-based; `None` when absent.
    pub boundary_faces: Option<Vec<[u32; 3]>>,
}

/// A validated tet mesh with its rest state.
///
/// Every tet is positively oriented (`det(Dm) > 0`) after construction.
#[derive(Debug, Clone)]
pub struct TetMesh {
    /// Rest (material) positions `X`, metres.
    pub rest_positions: Vec<Vec3>,
    /// Tet connectivity, positively oriented.
    pub tets: Vec<[u32; 4]>,
    /// Per-tet inverse rest shape matrix `Dm⁻¹` (PHYSICS.md §1.1).
    pub dm_inv: Vec<Mat3>,
    /// Per-tet rest volume `V = det(Dm)/6`, m³.
    pub rest_volume: Vec<f32>,
    /// For each tet and local face (opposite vertex f), the tet across that face.
    pub face_neighbors: Vec<[u32; 4]>,
    /// Faces with no neighbour, as (tet, local face) pairs.
    pub boundary: Vec<(u32, u8)>,
    /// CSR offsets into [`TetMesh::node_tet_list`]; node `i` owns `offsets[i]..offsets[i+1]`.
    pub node_tet_offsets: Vec<u32>,
    /// Tets incident to each node (CSR payload).
    pub node_tet_list: Vec<u32>,
}

impl TetMesh {
    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.rest_positions.len()
    }

    /// Number of tets.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// For each entry of the node→tet lists (node after node, as
    /// [`TetMesh::tets_of_node`] gives them; offsets [`TetMesh::node_tet_offsets`]), the
    /// tet and the node's corner in it (0–3).
    pub fn node_corners(&self) -> Vec<(u32, u8)> {
        (0..self.node_count())
            .flat_map(|i| {
                self.tets_of_node(i).iter().map(move |&t| {
                    let corner = self.tets[t as usize].iter().position(|&k| k as usize == i);
                    (t, corner.unwrap_or(0) as u8)
                })
            })
            .collect()
    }

    /// Tets incident to node `i`.
    pub fn tets_of_node(&self, i: usize) -> &[u32] {
        let a = self.node_tet_offsets[i] as usize;
        let b = self.node_tet_offsets[i + 1] as usize;
        &self.node_tet_list[a..b]
    }

    /// Global node indices of local face `f` of tet `t`, wound outward.
    pub fn face_nodes(&self, t: usize, f: usize) -> [u32; 3] {
        let tet = self.tets[t];
        TET_FACES[f].map(|l| tet[l])
    }

    /// Boundary faces as outward-wound node triples.
    pub fn boundary_triangles(&self) -> Vec<[u32; 3]> {
        self.boundary
            .iter()
            .map(|&(t, f)| self.face_nodes(t as usize, f as usize))
            .collect()
    }

    /// Total rest volume, m³.
    pub fn total_rest_volume(&self) -> f64 {
        self.rest_volume.iter().map(|&v| v as f64).sum()
    }

    /// Lumped node masses `m_i = Σ_{k ∋ i} ρ V_k / 4` for density `rho` (kg/m³).
    // PHYSICS.md §1.1, node mass.
    pub fn lumped_masses(&self, rho: f32) -> Vec<f32> {
        let mut m = vec![0.0f32; self.node_count()];
        for (tet, &v) in self.tets.iter().zip(&self.rest_volume) {
            for &n in tet {
                m[n as usize] += rho * v * 0.25;
            }
        }
        m
    }

    /// Axis-aligned bounds of the rest positions (min, max).
    pub fn rest_bounds(&self) -> (Vec3, Vec3) {
        bounds(&self.rest_positions)
    }

    /// Mean rest edge length over all tet edges (each edge counted once per tet).
    pub fn mean_edge_length(&self) -> f32 {
        let mut sum = 0.0f64;
        for t in &self.tets {
            for (a, b) in TET_EDGES {
                sum += (self.rest_positions[t[a] as usize] - self.rest_positions[t[b] as usize])
                    .length() as f64;
            }
        }
        (sum / (6.0 * self.tets.len().max(1) as f64)) as f32
    }
}

/// The six edges of a tet as local vertex pairs.
pub const TET_EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Axis-aligned bounds (min, max) of a point set; zero box when empty.
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    if points.is_empty() {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Shape matrix `[x1-x0, x2-x0, x3-x0]` (columns) of four points.
// PHYSICS.md §1.1 (Dm) and §1.2 (Ds).
#[inline]
pub fn shape_matrix(x0: Vec3, x1: Vec3, x2: Vec3, x3: Vec3) -> Mat3 {
    Mat3::from_cols(x1 - x0, x2 - x0, x3 - x0)
}
