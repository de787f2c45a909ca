//! The thin plate of Nakao et al. 2003 (PHYSICS.md §2.6).

use glam::{UVec3, Vec3};

use super::block;
use crate::mesh::RawMesh;

/// The Nakao 2003 plate, 16.0 × 16.0 × 0.4 cm: x/y in plane centred on the origin, z from
/// 0 to 0.004 m.
///
/// 24 × 24 × 1 hexes (25 × 25 × 2 nodes), 6 tets each: 1,250 nodes, 3,456 tets, 5,953
/// edges and 2,496 boundary triangles, against the paper's 1,274 nodes, 3,647 tets, 6,160
/// edges and 2,500 surface triangles. The paper's mesh is not a structured grid; this is
/// the structured choice closest to it (the surface triangle count matches almost exactly).
pub fn plate() -> RawMesh {
    block(
        Vec3::new(-0.08, -0.08, 0.0),
        Vec3::new(0.16, 0.16, 0.004),
        UVec3::new(24, 24, 1),
    )
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use super::*;
    use crate::mesh::{TET_EDGES, TetMesh};

    #[test]
    fn plate_matches_the_documented_counts() {
        let raw = plate();
        let edges: HashSet<(u32, u32)> = raw
            .tets
            .iter()
            .flat_map(|t| TET_EDGES.map(|(a, b)| (t[a].min(t[b]), t[a].max(t[b]))))
            .collect();
        assert_eq!(edges.len(), 5_953);
        let (mesh, report) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(report.reoriented_tets, 0);
        assert_eq!(mesh.node_count(), 1_250);
        assert_eq!(mesh.tet_count(), 3_456);
        assert_eq!(mesh.boundary.len(), 2_496);
        let (lo, hi) = mesh.rest_bounds();
        assert!(lo.abs_diff_eq(Vec3::new(-0.08, -0.08, 0.0), 1e-7));
        assert!(hi.abs_diff_eq(Vec3::new(0.08, 0.08, 0.004), 1e-7));
        assert!((mesh.total_rest_volume() - 0.16 * 0.16 * 0.004).abs() < 1e-9);
    }
}
