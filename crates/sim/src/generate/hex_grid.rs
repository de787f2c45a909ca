//! Structured hexahedral grids split into tets with the 6-tet Kuhn (Freudenthal) split.
//!
//! Every hex is cut into the six tets that follow a monotone path from its corner
//! `(0,0,0)` to its corner `(1,1,1)` in grid-index space. Because every hex uses the same
//! main diagonal, neighbouring hexes cut their shared face along the same diagonal, so the
//! result is conforming without the parity alternation the 5-tet split needs — also across
//! a periodic seam.

use glam::Vec3;

use crate::mesh::RawMesh;

/// The six Kuhn tets of a hex, as corner numbers `a + 2b + 4c` of corner `(a, b, c)`: each
/// one is the path `000 → 111` stepping along the three axes in one of the six orders.
const KUHN_TETS: [[usize; 4]; 6] = [
    [0, 1, 3, 7], // i, j, k
    [0, 1, 5, 7], // i, k, j
    [0, 2, 3, 7], // j, i, k
    [0, 2, 6, 7], // j, k, i
    [0, 4, 5, 7], // k, i, j
    [0, 4, 6, 7], // k, j, i
];

/// Tets of a structured `nodes[0] × nodes[1] × nodes[2]` grid of node positions `pos(i, j, k)`,
/// 6 per hex, each oriented to positive volume.
///
/// Node `(i, j, k)` gets index `i + n0·(j + n1·k)`. With `periodic_i` the first axis wraps
/// around (node `n0` is node `0`), as for the circumference of a tube; it then needs at
/// least 3 nodes. A grid with no cells, or too many nodes for `u32` indices, yields no tets
/// and a warning in [`RawMesh::warnings`].
pub fn hex_grid_tets(
    nodes: [usize; 3],
    periodic_i: bool,
    pos: impl Fn(usize, usize, usize) -> Vec3,
) -> RawMesh {
    let [n0, n1, n2] = nodes;
    let mut raw = RawMesh::default();
    let node_count = n0.checked_mul(n1).and_then(|n| n.checked_mul(n2));
    let Some(node_count) = node_count.filter(|&n| n <= u32::MAX as usize) else {
        raw.warnings.push(format!(
            "hex grid {n0}×{n1}×{n2} has too many nodes for 32-bit indices"
        ));
        return raw;
    };
    let cells = [
        match periodic_i {
            true if n0 >= 3 => n0,
            true => 0,
            false => n0.saturating_sub(1),
        },
        n1.saturating_sub(1),
        n2.saturating_sub(1),
    ];

    raw.positions.reserve(node_count);
    for k in 0..n2 {
        for j in 0..n1 {
            for i in 0..n0 {
                raw.positions.push(pos(i, j, k));
            }
        }
    }
    if cells.contains(&0) {
        raw.warnings.push(format!(
            "hex grid {n0}×{n1}×{n2} (periodic first axis: {periodic_i}) has no cells"
        ));
        return raw;
    }

    let index = |i: usize, j: usize, k: usize| (i % n0 + n0 * (j + n1 * k)) as u32;
    raw.tets.reserve(6 * cells[0] * cells[1] * cells[2]);
    for k in 0..cells[2] {
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                let corner: [u32; 8] =
                    std::array::from_fn(|c| index(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)));
                for local in KUHN_TETS {
                    let mut tet = local.map(|c| corner[c]);
                    if signed_volume6(&raw.positions, tet) < 0.0 {
                        tet.swap(2, 3);
                    }
                    raw.tets.push(tet);
                }
            }
        }
    }
    raw
}

/// Six times the signed volume of a tet, in f64.
fn signed_volume6(positions: &[Vec3], tet: [u32; 4]) -> f64 {
    let [p0, p1, p2, p3] = tet.map(|i| positions[i as usize].as_dvec3());
    (p1 - p0).dot((p2 - p0).cross(p3 - p0))
}

#[cfg(test)]
pub(crate) mod tests {
    use std::collections::HashMap;

    use super::*;
    use crate::mesh::{TET_FACES, TetMesh};

    /// Checks that every face is used once (boundary) or twice with opposite windings
    /// (interior), and returns the boundary face count.
    pub(crate) fn assert_conforming(raw: &RawMesh) -> usize {
        let mut faces: HashMap<[u32; 3], Vec<bool>> = HashMap::new();
        for tet in &raw.tets {
            for f in TET_FACES {
                let mut face = f.map(|l| tet[l]);
                // Sort by a bubble sort and track the permutation parity.
                let mut parity = false;
                for a in 0..3 {
                    for b in 0..2 - a {
                        if face[b] > face[b + 1] {
                            face.swap(b, b + 1);
                            parity = !parity;
                        }
                    }
                }
                faces.entry(face).or_default().push(parity);
            }
        }
        let mut boundary = 0;
        for (face, uses) in &faces {
            match uses.as_slice() {
                [_] => boundary += 1,
                [a, b] => assert_ne!(a, b, "face {face:?} is wound the same way twice"),
                _ => panic!("face {face:?} is used by {} tets", uses.len()),
            }
        }
        boundary
    }

    fn all_positive(raw: &RawMesh) -> bool {
        raw.tets
            .iter()
            .all(|&t| signed_volume6(&raw.positions, t) > 0.0)
    }

    #[test]
    fn box_grid_is_conforming_positive_and_fills_the_box() {
        // Deliberately left-handed index map: orientation must still come out positive.
        let raw = hex_grid_tets([4, 3, 5], false, |i, j, k| {
            Vec3::new(i as f32 * 0.5, -(j as f32) * 0.25, k as f32 * 0.2)
        });
        assert_eq!(raw.positions.len(), 4 * 3 * 5);
        assert_eq!(raw.tets.len(), 6 * 3 * 2 * 4);
        assert!(all_positive(&raw));
        let boundary = assert_conforming(&raw);
        assert_eq!(boundary, 2 * 2 * (3 * 2 + 2 * 4 + 4 * 3));
        let (mesh, report) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(report.reoriented_tets, 0);
        assert_eq!(mesh.boundary.len(), boundary);
        assert!((mesh.total_rest_volume() - 1.5 * 0.5 * 0.8).abs() < 1e-6);
    }

    #[test]
    fn periodic_ring_is_conforming_with_no_seam() {
        let n = 8;
        let raw = hex_grid_tets([n, 2, 3], true, |i, j, k| {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            let r = 1.0 + j as f32 * 0.3;
            Vec3::new(r * a.cos(), r * a.sin(), k as f32 * 0.4)
        });
        assert_eq!(raw.tets.len(), 6 * n * 2);
        assert!(all_positive(&raw));
        // Only the inner/outer and the two end faces are boundary: the seam is closed.
        let boundary = assert_conforming(&raw);
        assert_eq!(boundary, 2 * (2 * n * 2) + 2 * (2 * n));
    }

    #[test]
    fn grids_without_cells_give_no_tets_and_a_warning() {
        let raw = hex_grid_tets([1, 4, 4], false, |_, _, _| Vec3::ZERO);
        assert!(raw.tets.is_empty());
        assert_eq!(raw.warnings.len(), 1);
        let raw = hex_grid_tets([2, 2, 2], true, |_, _, _| Vec3::ZERO);
        assert!(raw.tets.is_empty());
        let raw = hex_grid_tets([usize::MAX, 2, 2], false, |_, _, _| Vec3::ZERO);
        assert!(raw.tets.is_empty() && raw.positions.is_empty());
    }
}
