//! Mesh quality figures for `incise mesh check`: sizes, volumes, dihedral angles and the
//! problems (inverted, degenerate, unused) that loading would fix or reject.

use glam::DVec3;

use super::topology::connected_components;
use super::{DEGENERATE_REL, RawMesh, TET_EDGES, TetMesh};

/// Quality figures of a raw mesh; volumes in m³ (file units cubed), angles in degrees.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MeshQuality {
    /// Number of nodes.
    pub nodes: usize,
    /// Number of tets.
    pub tets: usize,
    /// Boundary faces of the built mesh; `None` when it does not build.
    pub boundary_faces: Option<usize>,
    /// Connected components (tets sharing a node) of the built mesh; `None` when it does not build.
    pub components: Option<usize>,
    /// Why `TetMesh::from_raw` rejects the mesh; `None` when it builds.
    pub build_error: Option<String>,
    /// Smallest `|V|` over tets with valid node indices (0 when there are none).
    pub volume_min: f64,
    /// Largest `|V|` over tets with valid node indices (0 when there are none).
    pub volume_max: f64,
    /// Sum of `|V|` over tets with valid node indices.
    pub volume_total: f64,
    /// Smallest interior dihedral angle over non-degenerate tets (0 when there are none).
    pub dihedral_min_deg: f64,
    /// Largest interior dihedral angle over non-degenerate tets (0 when there are none).
    pub dihedral_max_deg: f64,
    /// Non-degenerate tets with negative signed volume in the input (loading re-orients them).
    pub inverted_tets: usize,
    /// Tets with `|V| < DEGENERATE_REL · ℓ̄³` (ℓ̄ the mean edge) or a non-finite volume.
    pub degenerate_tets: usize,
    /// Index of the first degenerate tet.
    pub first_degenerate: Option<usize>,
    /// Tets naming a node that does not exist (left out of every other figure).
    pub out_of_range_tets: usize,
    /// Nodes referenced by no tet.
    pub unused_nodes: usize,
}

/// Assess `raw` as it is, and as `TetMesh::from_raw` would build it (on a clone).
pub fn assess(raw: &RawMesh) -> MeshQuality {
    let n = raw.positions.len();
    let mut q = MeshQuality {
        nodes: n,
        tets: raw.tets.len(),
        boundary_faces: None,
        components: None,
        build_error: None,
        volume_min: f64::INFINITY,
        volume_max: 0.0,
        volume_total: 0.0,
        dihedral_min_deg: f64::INFINITY,
        dihedral_max_deg: 0.0,
        inverted_tets: 0,
        degenerate_tets: 0,
        first_degenerate: None,
        out_of_range_tets: 0,
        unused_nodes: 0,
    };
    let mut used = vec![false; n];
    for (t, tet) in raw.tets.iter().enumerate() {
        if tet.iter().any(|&v| v as usize >= n) {
            q.out_of_range_tets += 1;
            continue;
        }
        for &v in tet {
            used[v as usize] = true;
        }
        let p = tet.map(|i| raw.positions[i as usize].as_dvec3());
        let volume = signed_volume(p);
        let mean_edge = TET_EDGES
            .iter()
            .map(|&(a, b)| (p[b] - p[a]).length())
            .sum::<f64>()
            / 6.0;
        if !volume.is_finite() || volume.abs() < DEGENERATE_REL * mean_edge.powi(3) {
            q.degenerate_tets += 1;
            q.first_degenerate.get_or_insert(t);
        } else {
            if volume < 0.0 {
                q.inverted_tets += 1;
            }
            for angle in dihedral_angles_deg(p) {
                q.dihedral_min_deg = q.dihedral_min_deg.min(angle);
                q.dihedral_max_deg = q.dihedral_max_deg.max(angle);
            }
        }
        if volume.is_finite() {
            q.volume_min = q.volume_min.min(volume.abs());
            q.volume_max = q.volume_max.max(volume.abs());
            q.volume_total += volume.abs();
        }
    }
    if q.volume_min == f64::INFINITY {
        q.volume_min = 0.0;
    }
    if q.dihedral_min_deg == f64::INFINITY {
        q.dihedral_min_deg = 0.0;
    }
    q.unused_nodes = used.iter().filter(|&&u| !u).count();
    match TetMesh::from_raw(raw.clone()) {
        Ok((mesh, _)) => {
            q.boundary_faces = Some(mesh.boundary.len());
            q.components = Some(connected_components(&mesh, |_| true));
        }
        Err(e) => q.build_error = Some(e.to_string()),
    }
    q
}

/// Signed volume of the tet with corners `p`.
fn signed_volume(p: [DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
}

/// The six interior dihedral angles of the tet with corners `p`, degrees, one per edge.
pub fn dihedral_angles_deg(p: [DVec3; 4]) -> [f64; 6] {
    TET_EDGES.map(|(a, b)| {
        let (c, d) = match (a, b) {
            (0, 1) => (2, 3),
            (0, 2) => (1, 3),
            (0, 3) => (1, 2),
            (1, 2) => (0, 3),
            (1, 3) => (0, 2),
            _ => (0, 1),
        };
        let e = (p[b] - p[a]).normalize_or_zero();
        let u = p[c] - p[a];
        let v = p[d] - p[a];
        let (u, v) = (u - e * u.dot(e), v - e * v.dot(e));
        let cos = u.dot(v) / (u.length() * v.length());
        cos.clamp(-1.0, 1.0).acos().to_degrees()
    })
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::{block, plate};

    fn regular_tet() -> [DVec3; 4] {
        [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ]
    }

    #[test]
    fn regular_tet_has_all_dihedrals_arccos_one_third() {
        let expected = (1.0f64 / 3.0).acos().to_degrees();
        assert!((expected - 70.528_779).abs() < 1e-5);
        for angle in dihedral_angles_deg(regular_tet()) {
            assert!((angle - expected).abs() < 1e-9, "{angle}");
        }
        let raw = RawMesh {
            positions: regular_tet().map(|p| p.as_vec3()).to_vec(),
            tets: vec![[0, 1, 2, 3]],
            ..RawMesh::default()
        };
        let q = assess(&raw);
        assert!((q.dihedral_min_deg - expected).abs() < 1e-4);
        assert!((q.dihedral_max_deg - expected).abs() < 1e-4);
        assert!((q.volume_total - 8.0 / 3.0).abs() < 1e-9);
        assert_eq!(q.boundary_faces, Some(4));
        assert_eq!(q.components, Some(1));
    }

    #[test]
    fn kuhn_cube_split_has_45_60_90_degree_dihedrals() {
        let raw = block(Vec3::ZERO, Vec3::ONE, UVec3::ONE);
        for tet in &raw.tets {
            let mut angles = dihedral_angles_deg(tet.map(|i| raw.positions[i as usize].as_dvec3()));
            angles.sort_by(f64::total_cmp);
            let expected = [45.0, 45.0, 60.0, 90.0, 90.0, 90.0];
            for (a, e) in angles.iter().zip(expected) {
                assert!((a - e).abs() < 1e-5, "{angles:?}");
            }
        }
        let q = assess(&raw);
        assert_eq!((q.nodes, q.tets), (8, 6));
        assert!((q.dihedral_min_deg - 45.0).abs() < 1e-5);
        assert!((q.dihedral_max_deg - 90.0).abs() < 1e-5);
        assert!((q.volume_min - 1.0 / 6.0).abs() < 1e-7);
        assert!((q.volume_max - 1.0 / 6.0).abs() < 1e-7);
        assert!((q.volume_total - 1.0).abs() < 1e-6);
        assert_eq!(q.boundary_faces, Some(12));
        assert_eq!(q.components, Some(1));
        assert_eq!(
            (q.inverted_tets, q.degenerate_tets, q.unused_nodes),
            (0, 0, 0)
        );
        assert!(q.build_error.is_none());
    }

    #[test]
    fn inverted_degenerate_and_unused_are_counted() {
        let raw = RawMesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::Z,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::splat(5.0),
            ],
            tets: vec![[0, 1, 2, 3], [0, 2, 1, 3], [1, 2, 4, 0], [0, 1, 2, 9]],
            ..RawMesh::default()
        };
        let q = assess(&raw);
        assert_eq!(q.inverted_tets, 1);
        assert_eq!(q.degenerate_tets, 1);
        assert_eq!(q.first_degenerate, Some(2));
        assert_eq!(q.out_of_range_tets, 1);
        assert_eq!(q.unused_nodes, 1);
        assert_eq!(q.boundary_faces, None);
        assert_eq!(q.components, None);
        assert!(
            q.build_error
                .as_deref()
                .unwrap()
                .contains("tet 2 is degenerate")
        );
        assert!((q.volume_min - 0.0).abs() < 1e-12);
        assert!((q.volume_total - 1.0 / 3.0).abs() < 1e-9);
    }

    #[test]
    fn generated_plate_is_clean() {
        let q = assess(&plate());
        assert_eq!(q.components, Some(1));
        assert_eq!(q.unused_nodes, 0);
        assert_eq!(q.inverted_tets, 0);
        assert!(q.dihedral_min_deg > 1.0 && q.dihedral_max_deg < 179.0);
    }
}
