//! Building a `TetMesh` from a `RawMesh`: validation, re-orientation, rest data, adjacency.

use std::collections::HashMap;

use super::{NO_NEIGHBOR, RawMesh, TET_FACES, TetMesh, shape_matrix};
use crate::MeshError;

/// What building the mesh changed or noticed.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct MeshBuildReport {
    /// Tets whose vertex order was swapped because their volume was negative.
    pub reoriented_tets: usize,
    /// Reader warnings carried over (skipped element types and similar).
    pub warnings: Vec<String>,
}

/// Relative volume below which a tet counts as degenerate: `|V| < DEGENERATE_REL · ℓ³`,
/// with ℓ the tet's mean edge length (a regular tet has `V ≈ 0.118 ℓ³`).
pub const DEGENERATE_REL: f64 = 1e-6;

impl TetMesh {
    /// Validate `raw` and compute rest data.
    ///
    /// Inverted tets are re-oriented by swapping their last two vertices (counted in the
    /// report); a tet whose volume is below tolerance is an error naming its index.
    pub fn from_raw(raw: RawMesh) -> Result<(TetMesh, MeshBuildReport), MeshError> {
        let RawMesh {
            positions,
            mut tets,
            warnings,
            ..
        } = raw;
        if positions.len() < 4 || tets.is_empty() {
            return Err(MeshError::Empty {
                nodes: positions.len(),
                tets: tets.len(),
            });
        }
        if let Some(node) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFiniteNode { node });
        }
        let n = positions.len();
        let mut reoriented = 0;
        let mut dm_inv = Vec::with_capacity(tets.len());
        let mut rest_volume = Vec::with_capacity(tets.len());
        for (ti, tet) in tets.iter_mut().enumerate() {
            for (k, &v) in tet.iter().enumerate() {
                if v as usize >= n {
                    return Err(MeshError::NodeIndexOutOfRange {
                        tet: ti,
                        node: v as u64,
                        count: n,
                    });
                }
                if tet[..k].contains(&v) {
                    return Err(MeshError::RepeatedNode { tet: ti, node: v });
                }
            }
            // Volume in f64 so that large coordinates do not hide a small tet.
            let p = tet.map(|i| positions[i as usize].as_dvec3());
            let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
            let vol6 = e1.dot(e2.cross(e3));
            let mean_edge = [e1, e2, e3, p[2] - p[1], p[3] - p[1], p[3] - p[2]]
                .iter()
                .map(|e| e.length())
                .sum::<f64>()
                / 6.0;
            let tolerance = DEGENERATE_REL * mean_edge.powi(3);
            if (vol6 / 6.0).abs() < tolerance || !vol6.is_finite() {
                return Err(MeshError::DegenerateTet {
                    tet: ti,
                    volume: vol6 / 6.0,
                    tolerance,
                });
            }
            if vol6 < 0.0 {
                tet.swap(2, 3);
                reoriented += 1;
            }
            let [x0, x1, x2, x3] = tet.map(|i| positions[i as usize]);
            let dm = shape_matrix(x0, x1, x2, x3);
            dm_inv.push(dm.inverse());
            rest_volume.push((vol6.abs() / 6.0) as f32);
        }

        let (node_tet_offsets, node_tet_list) = node_tet_csr(n, &tets);
        let mut warnings = warnings;
        let unreferenced = node_tet_offsets.windows(2).filter(|w| w[0] == w[1]).count();
        if unreferenced > 0 {
            warnings.push(format!(
                "{unreferenced} unreferenced node(s) in no tet: kept for indexing, not simulated"
            ));
        }
        let face_neighbors = face_neighbors(&tets);
        let boundary = face_neighbors
            .iter()
            .enumerate()
            .flat_map(|(t, nb)| {
                (0..4)
                    .filter(move |&f| nb[f] == NO_NEIGHBOR)
                    .map(move |f| (t as u32, f as u8))
            })
            .collect();
        let mesh = TetMesh {
            rest_positions: positions,
            tets,
            dm_inv,
            rest_volume,
            face_neighbors,
            boundary,
            node_tet_offsets,
            node_tet_list,
        };
        Ok((
            mesh,
            MeshBuildReport {
                reoriented_tets: reoriented,
                warnings,
            },
        ))
    }
}

/// Node → incident tets, as CSR (offsets, list).
fn node_tet_csr(n: usize, tets: &[[u32; 4]]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; n + 1];
    for tet in tets {
        for &v in tet {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut list = vec![0u32; tets.len() * 4];
    for (t, tet) in tets.iter().enumerate() {
        for &v in tet {
            list[fill[v as usize] as usize] = t as u32;
            fill[v as usize] += 1;
        }
    }
    (offsets, list)
}

/// For each tet face, the tet sharing it (or `NO_NEIGHBOR`). A face shared by more than
/// two tets (non-manifold input) links only the first two.
fn face_neighbors(tets: &[[u32; 4]]) -> Vec<[u32; 4]> {
    let mut out = vec![[NO_NEIGHBOR; 4]; tets.len()];
    let mut open: HashMap<[u32; 3], (u32, u8)> = HashMap::with_capacity(tets.len() * 2);
    for (t, tet) in tets.iter().enumerate() {
        for (f, face) in TET_FACES.iter().enumerate() {
            let mut key = face.map(|l| tet[l]);
            key.sort_unstable();
            match open.remove(&key) {
                Some((u, g)) => {
                    out[t][f] = u;
                    out[u as usize][g as usize] = t as u32;
                }
                None => {
                    open.insert(key, (t as u32, f as u8));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn unit_tet() -> RawMesh {
        RawMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            tets: vec![[0, 1, 2, 3]],
            warnings: vec![],
            boundary_faces: None,
        }
    }

    #[test]
    fn inverted_tet_is_reoriented_and_counted() {
        let mut raw = unit_tet();
        raw.tets[0] = [0, 2, 1, 3];
        let (mesh, report) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(report.reoriented_tets, 1);
        assert!((mesh.rest_volume[0] - 1.0 / 6.0).abs() < 1e-7);
        assert_eq!(mesh.boundary.len(), 4);
    }

    #[test]
    fn flat_tet_is_an_error_naming_it() {
        let mut raw = unit_tet();
        raw.positions.push(Vec3::new(1.0, 1.0, 0.0));
        raw.tets.push([1, 2, 4, 0]);
        let err = TetMesh::from_raw(raw).unwrap_err();
        assert!(err.to_string().starts_with("tet 1 is degenerate"), "{err}");
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let mut raw = unit_tet();
        raw.tets[0][3] = 9;
        let err = TetMesh::from_raw(raw).unwrap_err();
        assert!(matches!(
            err,
            MeshError::NodeIndexOutOfRange { node: 9, .. }
        ));
    }

    #[test]
    fn two_tets_share_one_interior_face() {
        let raw = RawMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE],
            tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
            warnings: vec![],
            boundary_faces: None,
        };
        let (mesh, _) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(mesh.boundary.len(), 6);
        assert_eq!(mesh.tets_of_node(1), &[0, 1]);
        assert_eq!(mesh.face_neighbors[0][0], 1);
    }
}
