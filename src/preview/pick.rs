//! Picking the tissue under the cursor: the nearest hit of a ray on the visible faces of
//! the live tets (outer skin and cut walls, at the current positions).

use glam::Vec3;
use incise_sim::TetMesh;
use incise_sim::cutting::CutState;

/// Distance `s > 0` along `origin + s·dir` to triangle `[a, b, c]` (either side), or
/// `None` (Möller–Trumbore).
pub fn ray_triangle(origin: Vec3, dir: Vec3, [a, b, c]: [Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let t = origin - a;
    let u = t.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = t.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let s = e2.dot(q) * inv;
    (s > 0.0).then_some(s)
}

/// The nearest point where the ray meets the tissue's visible faces, or `None`.
pub fn pick_tissue(
    origin: Vec3,
    dir: Vec3,
    mesh: &TetMesh,
    cut: &CutState,
    positions: &[Vec3],
) -> Option<Vec3> {
    cut.visible_faces()
        .iter()
        .filter_map(|&(t, f)| {
            let tri = mesh
                .face_nodes(t as usize, f as usize)
                .map(|i| positions[i as usize]);
            ray_triangle(origin, dir, tri)
        })
        .min_by(f32::total_cmp)
        .map(|s| origin + dir * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::UVec3;
    use incise_sim::generate::block;

    #[test]
    fn a_ray_hits_a_triangle_where_hand_computation_says() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        // From (0.25, 0.25, 2) straight down: 2 m to the hit.
        let s = ray_triangle(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, tri).unwrap();
        assert!((s - 2.0).abs() < 1e-6);
        // Outside the triangle (u + v > 1), pointing away, or parallel: no hit.
        assert!(ray_triangle(Vec3::new(0.8, 0.8, 2.0), -Vec3::Z, tri).is_none());
        assert!(ray_triangle(Vec3::new(0.25, 0.25, 2.0), Vec3::Z, tri).is_none());
        assert!(ray_triangle(Vec3::new(0.25, 0.25, 2.0), Vec3::X, tri).is_none());
    }

    #[test]
    fn picking_finds_the_top_of_a_block_and_misses_beside_it() {
        let raw = block(Vec3::ZERO, Vec3::new(0.08, 0.04, 0.02), UVec3::new(8, 4, 2));
        let (mesh, _) = TetMesh::from_raw(raw).unwrap();
        let cut = CutState::new(&mesh);
        let x = mesh.rest_positions.clone();
        // A slanted ray from above: it meets the top z = 0.02 first, at s = 0.08 / 0.8,
        // x = 0.01 + 0.1 · 0.6.
        let dir = Vec3::new(0.6, 0.0, -0.8);
        let hit = pick_tissue(Vec3::new(0.01, 0.02, 0.1), dir, &mesh, &cut, &x).unwrap();
        assert!((hit - Vec3::new(0.07, 0.02, 0.02)).length() < 1e-6, "{hit}");
        // From below, it meets the bottom z = 0 instead.
        let up = pick_tissue(Vec3::new(0.03, 0.02, -0.05), Vec3::Z, &mesh, &cut, &x).unwrap();
        assert!((up - Vec3::new(0.03, 0.02, 0.0)).length() < 1e-6, "{up}");
        assert!(pick_tissue(Vec3::new(0.2, 0.02, 0.12), -Vec3::Z, &mesh, &cut, &x).is_none());
    }
}
