//! Meshes drawn for tools: any closed triangle mesh the application hands over (the
//! scalpel's own, flat-shaded by [`ToolMesh::from_triangles`]), the simple stand-in blade
//! drawn until it does, and the unit sphere that marker instances scale.

use glam::Vec3;

/// An indexed triangle mesh with per-vertex normals, in its own frame (metres).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ToolMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Triangles, counter-clockwise seen from outside.
    pub indices: Vec<[u32; 3]>,
}

impl ToolMesh {
    /// A flat-shaded mesh from plain vertices and counter-clockwise-outward triangles in
    /// the tool's own frame (m): each triangle gets its own three vertices and its face
    /// normal. Triangles naming a vertex that does not exist are skipped.
    pub fn from_triangles(positions: &[Vec3], triangles: &[[u32; 3]]) -> ToolMesh {
        let mut m = ToolMesh::default();
        for t in triangles {
            if let [Some(&a), Some(&b), Some(&c)] = t.map(|i| positions.get(i as usize)) {
                m.add_triangle([a, b, c]);
            }
        }
        m
    }

    /// A simple scalpel: the blade in the x-z plane with its tip at the origin and its
    /// cutting edge running back along −x just above it, the handle rising behind. Its
    /// contact point is the origin. Flat-shaded.
    pub fn scalpel() -> ToolMesh {
        let mut m = ToolMesh::default();
        // Blade: a thin curved-belly plate in the x-z plane, 0.4 mm thick.
        let t = 0.0002;
        let outline = [
            (0.0, 0.0),
            (-0.006, 0.002),
            (-0.014, 0.006),
            (-0.022, 0.010),
            (-0.028, 0.011),
            (-0.028, 0.016),
            (-0.012, 0.014),
            (0.0, 0.0),
        ];
        m.add_prism(&outline[..outline.len() - 1], t);
        // Handle: a box from behind the blade upwards and back.
        m.add_box(
            Vec3::new(-0.030, 0.0, 0.012),
            Vec3::new(0.008, 0.004, 0.080),
            0.5,
        );
        m
    }

    /// Append a closed prism: the convex-ish polygon `outline` (x, z) extruded ±`half` in y.
    fn add_prism(&mut self, outline: &[(f32, f32)], half: f32) {
        let pts: Vec<(Vec3, Vec3)> = outline
            .iter()
            .map(|&(x, z)| (Vec3::new(x, -half, z), Vec3::new(x, half, z)))
            .collect();
        // Side faces.
        for i in 0..pts.len() {
            let (a0, a1) = pts[i];
            let (b0, b1) = pts[(i + 1) % pts.len()];
            self.add_quad([a0, b0, b1, a1]);
        }
        // Caps: fans from the first point.
        for i in 1..pts.len() - 1 {
            self.add_triangle([pts[0].1, pts[i].1, pts[i + 1].1]);
            self.add_triangle([pts[0].0, pts[i + 1].0, pts[i].0]);
        }
    }

    /// Append a box with lower-back corner `origin` and edge lengths `size`, tilted by
    /// `tilt` radians about y so the handle leans back.
    fn add_box(&mut self, origin: Vec3, size: Vec3, tilt: f32) {
        let rot = glam::Quat::from_rotation_y(-tilt);
        let c = |x: f32, y: f32, z: f32| {
            origin + rot * Vec3::new(x * size.x, (y - 0.5) * size.y, z * size.z)
        };
        let v = [
            c(0., 0., 0.),
            c(1., 0., 0.),
            c(1., 1., 0.),
            c(0., 1., 0.),
            c(0., 0., 1.),
            c(1., 0., 1.),
            c(1., 1., 1.),
            c(0., 1., 1.),
        ];
        for q in [
            [0, 3, 2, 1],
            [4, 5, 6, 7],
            [0, 1, 5, 4],
            [2, 3, 7, 6],
            [1, 2, 6, 5],
            [0, 4, 7, 3],
        ] {
            self.add_quad(q.map(|i| v[i]));
        }
    }

    fn add_quad(&mut self, q: [Vec3; 4]) {
        self.add_triangle([q[0], q[1], q[2]]);
        self.add_triangle([q[0], q[2], q[3]]);
    }

    fn add_triangle(&mut self, t: [Vec3; 3]) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        let base = self.positions.len() as u32;
        self.positions.extend(t);
        self.normals.extend([n; 3]);
        self.indices.push([base, base + 1, base + 2]);
    }

    /// A unit icosphere subdivided `levels` times (normals = positions).
    pub fn unit_sphere(levels: u32) -> ToolMesh {
        let p = (1.0 + 5f32.sqrt()) / 2.0;
        let mut positions: Vec<Vec3> = [
            (-1., p, 0.),
            (1., p, 0.),
            (-1., -p, 0.),
            (1., -p, 0.),
            (0., -1., p),
            (0., 1., p),
            (0., -1., -p),
            (0., 1., -p),
            (p, 0., -1.),
            (p, 0., 1.),
            (-p, 0., -1.),
            (-p, 0., 1.),
        ]
        .iter()
        .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
        .collect();
        let mut indices: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..levels {
            let mut mid = std::collections::HashMap::new();
            let mut midpoint = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    positions
                        .push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
                    positions.len() as u32 - 1
                })
            };
            let mut next = Vec::with_capacity(indices.len() * 4);
            for [a, b, c] in indices {
                let ab = midpoint(a, b, &mut positions);
                let bc = midpoint(b, c, &mut positions);
                let ca = midpoint(c, a, &mut positions);
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            indices = next;
        }
        ToolMesh {
            normals: positions.clone(),
            positions,
            indices,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum over triangles of (centroid · area normal) / 3 = enclosed volume, positive when
    /// every triangle is wound outward.
    fn signed_volume(m: &ToolMesh) -> f32 {
        m.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn meshes_are_closed_and_wound_outward() {
        let s = ToolMesh::unit_sphere(2);
        assert_eq!(s.indices.len(), 20 * 16);
        let v = signed_volume(&s);
        // Inscribed in the unit sphere: a little less than its volume.
        let ball = 4.0 / 3.0 * std::f32::consts::PI;
        assert!(v < ball && v > 0.95 * ball, "{v}");
        assert!(s.positions.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
        let k = ToolMesh::scalpel();
        assert!(signed_volume(&k) > 0.0);
        assert_eq!(k.positions.len(), k.normals.len());
        assert!(k.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        // The tip is the lowest point of the blade, at the origin.
        let lowest = k
            .positions
            .iter()
            .map(|p| p.z)
            .fold(f32::INFINITY, f32::min);
        assert!(lowest.abs() < 1e-6, "{lowest}");
    }

    #[test]
    fn an_arbitrary_mesh_is_flat_shaded_per_face() {
        // A unit right tetrahedron, wound outward; one bad triangle is skipped.
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let tris = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 9]];
        let m = ToolMesh::from_triangles(&p, &tris);
        assert_eq!(m.indices.len(), 4);
        assert_eq!(m.positions.len(), 12);
        // The face x + y + z = 1 has normal (1, 1, 1)/√3 on all three of its vertices.
        let n = Vec3::ONE.normalize();
        assert!(m.normals[9..12].iter().all(|v| (*v - n).length() < 1e-6));
        assert!(
            m.normals[0..3]
                .iter()
                .all(|v| (*v + Vec3::Z).length() < 1e-6)
        );
        assert!((signed_volume(&m) - 1.0 / 6.0).abs() < 1e-6);
    }
}
