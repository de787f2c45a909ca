//! A torso-like test body for the Nakao chest experiment (PHYSICS.md §2.6: the paper's
//! chest wall + heart from MRI has 17,582 nodes, 100,807 edges and 73,279 tets): a chest
//! wall curved over an elliptic arc and a heart-sized ellipsoid inside it, as two
//! structured Kuhn grids sized so that the node count is the paper's and the tet count
//! within 0.4 % of it.

use glam::Vec3;

use super::hex_grid_tets;
use crate::mesh::RawMesh;

/// Nodes of the wall around the arc, along the body and through its thickness.
pub const CHEST_WALL_NODES: [usize; 3] = [103, 41, 3];
/// Nodes per axis of the heart's grid.
pub const CHEST_HEART_NODES: usize = 17;
/// Semi-axes of the wall's inner ellipse (lateral x, antero-posterior z), m.
pub const CHEST_WALL_AXES: [f32; 2] = [0.15, 0.10];
/// Wall thickness, m.
pub const CHEST_WALL_THICKNESS: f32 = 0.02;
/// Length of the wall along the body (y), m.
pub const CHEST_LENGTH: f32 = 0.30;
/// The arc the wall spans, from the right side over the sternum to the left, radians
/// (θ = π/2 is the sternum, the top).
pub const CHEST_ARC: [f32; 2] = [0.35, std::f32::consts::PI - 0.35];
/// Centre and semi-axes of the heart, m.
pub const CHEST_HEART: (Vec3, Vec3) = (Vec3::new(0.02, 0.0, 0.02), Vec3::new(0.05, 0.06, 0.045));

/// The wall (nodes first) and the heart, one mesh: 17,582 nodes, 73,536 tets.
pub fn chest() -> RawMesh {
    let [na, nl, nt] = CHEST_WALL_NODES;
    let [a, b] = CHEST_WALL_AXES;
    let wall = hex_grid_tets(CHEST_WALL_NODES, false, |i, j, k| {
        let th = CHEST_ARC[0] + (CHEST_ARC[1] - CHEST_ARC[0]) * i as f32 / (na - 1) as f32;
        let s = CHEST_WALL_THICKNESS * k as f32 / (nt - 1) as f32;
        let y = CHEST_LENGTH * (j as f32 / (nl - 1) as f32 - 0.5);
        Vec3::new((a + s) * th.cos(), y, (b + s) * th.sin())
    });
    let h = CHEST_HEART_NODES;
    let (centre, radii) = CHEST_HEART;
    let heart = hex_grid_tets([h; 3], false, |i, j, k| {
        let u = [i, j, k].map(|c| 2.0 * c as f32 / (h - 1) as f32 - 1.0);
        centre + radii * cube_to_ball(Vec3::from(u))
    });
    let mut raw = wall;
    let offset = raw.positions.len() as u32;
    raw.positions.extend(heart.positions);
    raw.tets
        .extend(heart.tets.iter().map(|t| t.map(|v| v + offset)));
    raw.warnings.extend(heart.warnings);
    raw
}

/// The smooth map of the cube `[-1, 1]³` onto the unit ball (each face to a sixth of the
/// sphere), whose Jacobian stays positive.
fn cube_to_ball(p: Vec3) -> Vec3 {
    let (x2, y2, z2) = (p.x * p.x, p.y * p.y, p.z * p.z);
    Vec3::new(
        p.x * (1.0 - y2 / 2.0 - z2 / 2.0 + y2 * z2 / 3.0).sqrt(),
        p.y * (1.0 - z2 / 2.0 - x2 / 2.0 + z2 * x2 / 3.0).sqrt(),
        p.z * (1.0 - x2 / 2.0 - y2 / 2.0 + x2 * y2 / 3.0).sqrt(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TetMesh;

    #[test]
    fn chest_has_the_papers_node_count_and_valid_tets() {
        let raw = chest();
        assert_eq!(raw.positions.len(), 17_582);
        assert_eq!(raw.tets.len(), 73_536);
        let (mesh, report) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(mesh.tet_count(), 73_536);
        assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    }
}
