//! Axis-aligned boxes and beams of Kuhn-split hexes.

use glam::{UVec3, Vec3};

use super::hex_grid_tets;
use crate::mesh::RawMesh;

/// A box from `min` to `min + size` of `cells` hexes (6 tets each), metres.
///
/// A zero cell count along an axis gives a mesh without tets and a warning.
pub fn block(min: Vec3, size: Vec3, cells: UVec3) -> RawMesh {
    let step = size / cells.as_vec3().max(Vec3::ONE);
    let nodes = [cells.x, cells.y, cells.z].map(|c| c as usize + 1);
    hex_grid_tets(nodes, false, |i, j, k| {
        min + step * Vec3::new(i as f32, j as f32, k as f32)
    })
}

/// A beam along +x from `x = 0` to `x = length`, centred on the x axis in y and z.
pub fn beam(length: f32, width: f32, height: f32, cells: UVec3) -> RawMesh {
    block(
        Vec3::new(0.0, -0.5 * width, -0.5 * height),
        Vec3::new(length, width, height),
        cells,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::hex_grid::tests::assert_conforming;
    use crate::mesh::TetMesh;

    #[test]
    fn block_counts_bounds_and_volume() {
        let raw = block(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(2.0, 1.0, 0.5),
            UVec3::new(4, 2, 1),
        );
        assert_eq!(raw.positions.len(), 5 * 3 * 2);
        assert_eq!(raw.tets.len(), 6 * 8);
        assert_conforming(&raw);
        let (mesh, report) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(report.reoriented_tets, 0);
        let (lo, hi) = mesh.rest_bounds();
        assert!(lo.abs_diff_eq(Vec3::new(1.0, 2.0, 3.0), 1e-6));
        assert!(hi.abs_diff_eq(Vec3::new(3.0, 3.0, 3.5), 1e-6));
        assert!((mesh.total_rest_volume() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn beam_starts_at_origin_and_is_centred() {
        let raw = beam(0.1, 0.02, 0.01, UVec3::new(10, 2, 2));
        let (mesh, _) = TetMesh::from_raw(raw).unwrap();
        let (lo, hi) = mesh.rest_bounds();
        assert!(lo.abs_diff_eq(Vec3::new(0.0, -0.01, -0.005), 1e-7));
        assert!(hi.abs_diff_eq(Vec3::new(0.1, 0.01, 0.005), 1e-7));
    }

    #[test]
    fn zero_cells_give_an_empty_mesh_not_a_panic() {
        let raw = block(Vec3::ZERO, Vec3::ONE, UVec3::new(3, 0, 3));
        assert!(raw.tets.is_empty());
        assert_eq!(raw.warnings.len(), 1);
        assert!(TetMesh::from_raw(raw).is_err());
    }
}
