//! Which material each tet and edge of a body takes: a default, overridden region by
//! region (e.g. an organ whose outer layer is viscoelastic and whose core is rheological).

use crate::mesh::{EdgeList, TET_EDGES, TetMesh};
use crate::selection::NodeSelection;

use super::error::RheologyError;

/// The part of a mesh a region covers.
#[derive(Debug, Clone, PartialEq)]
pub enum RegionShape {
    /// The tets whose four nodes are all selected (by rest position or index).
    Nodes(NodeSelection),
    /// Explicit 0-based tet indices.
    Tets(Vec<u32>),
}

/// A region and the material (index into the body's material list) it takes.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialRegion {
    /// Which tets.
    pub shape: RegionShape,
    /// Index of the material.
    pub material: usize,
}

/// Material index of every tet and every edge.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialMap {
    /// Material of each tet (density, node masses).
    pub tet_material: Vec<u32>,
    /// Material of each edge (element constants).
    pub edge_material: Vec<u32>,
}

impl MaterialMap {
    /// Material 0 everywhere.
    pub fn uniform(mesh: &TetMesh, edges: &EdgeList) -> Self {
        MaterialMap {
            tet_material: vec![0; mesh.tet_count()],
            edge_material: vec![0; edges.len()],
        }
    }

    /// `default` everywhere, then each region in order; a later region wins. An edge takes
    /// the material of the latest region among the tets that contain it, so an interface
    /// edge belongs to the region listed last. A region that covers no tet (a node
    /// selection with no tet wholly inside it, an empty tet list) is an error: it is
    /// almost certainly a wrong coordinate or unit.
    pub fn from_regions(
        mesh: &TetMesh,
        edges: &EdgeList,
        default: usize,
        regions: &[MaterialRegion],
        material_count: usize,
    ) -> Result<Self, RheologyError> {
        let check = |index: usize| {
            if index < material_count {
                Ok(index as u32)
            } else {
                Err(RheologyError::MaterialIndex {
                    index,
                    count: material_count,
                })
            }
        };
        // Priority 0 = default; region r has priority r + 1.
        let mut tet_priority = vec![0usize; mesh.tet_count()];
        for (r, region) in regions.iter().enumerate() {
            check(region.material)?;
            let what = || format!("material region {r}");
            match &region.shape {
                RegionShape::Nodes(selection) => {
                    let picked = selection.select(&mesh.rest_positions).map_err(|source| {
                        RheologyError::Selection {
                            what: what(),
                            source,
                        }
                    })?;
                    let mut inside = vec![false; mesh.node_count()];
                    for &n in &picked {
                        inside[n as usize] = true;
                    }
                    let mut covered = 0;
                    for (t, tet) in mesh.tets.iter().enumerate() {
                        if tet.iter().all(|&n| inside[n as usize]) {
                            tet_priority[t] = r + 1;
                            covered += 1;
                        }
                    }
                    if covered == 0 {
                        return Err(RheologyError::EmptyRegion {
                            region: r,
                            why: format!(
                                "its {} selected nodes include all four nodes of no tet",
                                picked.len()
                            ),
                        });
                    }
                }
                RegionShape::Tets(list) => {
                    if list.is_empty() {
                        return Err(RheologyError::EmptyRegion {
                            region: r,
                            why: "its tet list is empty".into(),
                        });
                    }
                    for &t in list {
                        if t as usize >= mesh.tet_count() {
                            return Err(RheologyError::Selection {
                                what: what(),
                                source: crate::selection::SelectionError::OutOfRange {
                                    index: t,
                                    count: mesh.tet_count(),
                                },
                            });
                        }
                        tet_priority[t as usize] = r + 1;
                    }
                }
            }
        }
        let material_of = |priority: usize| match priority {
            0 => check(default),
            p => Ok(regions[p - 1].material as u32),
        };
        let mut edge_priority = vec![0usize; edges.len()];
        for (tet, &priority) in mesh.tets.iter().zip(&tet_priority) {
            for (a, b) in TET_EDGES {
                let e = edge_index(edges, tet[a], tet[b]);
                edge_priority[e] = edge_priority[e].max(priority);
            }
        }
        Ok(MaterialMap {
            tet_material: tet_priority
                .iter()
                .map(|&p| material_of(p))
                .collect::<Result<_, _>>()?,
            edge_material: edge_priority
                .iter()
                .map(|&p| material_of(p))
                .collect::<Result<_, _>>()?,
        })
    }

    /// Lumped node masses `m_i = Σ_{tets k ∋ i} ρ_k V_k / 4` with each tet's own density.
    // PHYSICS.md §1.1, node mass.
    pub fn node_masses(&self, mesh: &TetMesh, densities: &[f64]) -> Vec<f64> {
        let mut m = vec![0.0f64; mesh.node_count()];
        for ((tet, &v), &mat) in mesh
            .tets
            .iter()
            .zip(&mesh.rest_volume)
            .zip(&self.tet_material)
        {
            for &n in tet {
                m[n as usize] += densities[mat as usize] * v as f64 * 0.25;
            }
        }
        m
    }
}

/// Index of the edge joining nodes `i` and `j` (both in one tet, so it exists).
fn edge_index(edges: &EdgeList, i: u32, j: u32) -> usize {
    let key = [i.min(j), i.max(j)];
    edges
        .edges_of_node(i as usize)
        .iter()
        .map(|&e| e as usize)
        .find(|&e| edges.edges[e] == key)
        .expect("every tet edge is in the mesh's edge list")
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;

    fn cube() -> (TetMesh, EdgeList) {
        let mesh = TetMesh::from_raw(block(Vec3::ZERO, Vec3::splat(3.0), UVec3::splat(3)))
            .unwrap()
            .0;
        let edges = EdgeList::of_mesh(&mesh);
        (mesh, edges)
    }

    #[test]
    fn core_region_overrides_the_default_and_the_interface_goes_to_it() {
        let (mesh, edges) = cube();
        let core = MaterialRegion {
            shape: RegionShape::Nodes(NodeSelection::Box {
                min: Vec3::splat(0.9),
                max: Vec3::splat(2.1),
            }),
            material: 1,
        };
        let map = MaterialMap::from_regions(&mesh, &edges, 0, &[core], 2).unwrap();
        // The centre cell's 6 tets are core; every other tet is the outer layer.
        assert_eq!(map.tet_material.iter().filter(|&&m| m == 1).count(), 6);
        // Core edges: the 12 cube edges + 6 face diagonals + 1 body diagonal of the cell.
        assert_eq!(map.edge_material.iter().filter(|&&m| m == 1).count(), 19);
        let masses = map.node_masses(&mesh, &[1000.0, 2000.0]);
        let total: f64 = masses.iter().sum();
        assert!((total / 28_000.0 - 1.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn bad_indices_are_errors() {
        let (mesh, edges) = cube();
        let tets = |list: Vec<u32>, material| MaterialRegion {
            shape: RegionShape::Tets(list),
            material,
        };
        let e = MaterialMap::from_regions(&mesh, &edges, 0, &[tets(vec![0], 3)], 2);
        assert!(matches!(
            e,
            Err(RheologyError::MaterialIndex { index: 3, count: 2 })
        ));
        let e = MaterialMap::from_regions(&mesh, &edges, 0, &[tets(vec![999], 1)], 2);
        assert!(e.unwrap_err().to_string().contains("material region 0"));
        let e =
            MaterialMap::from_regions(&mesh, &edges, 0, &[tets(vec![0], 1), tets(vec![], 1)], 2);
        assert!(matches!(
            e,
            Err(RheologyError::EmptyRegion { region: 1, .. })
        ));
    }

    #[test]
    fn node_region_without_a_whole_tet_is_an_error() {
        let (mesh, edges) = cube();
        // The four bottom corners of one cell: nodes picked, but no tet has all four.
        let sliver = MaterialRegion {
            shape: RegionShape::Nodes(NodeSelection::Box {
                min: Vec3::splat(-0.1),
                max: Vec3::new(1.1, 1.1, 0.1),
            }),
            material: 1,
        };
        let e = MaterialMap::from_regions(&mesh, &edges, 0, &[sliver], 2).unwrap_err();
        assert!(
            matches!(e, RheologyError::EmptyRegion { region: 0, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("no tet"), "{e}");
    }
}
