//! The test specimen of the seed's press-and-release: a block standing on a table (bottom
//! face pinned), pressed on its top face.

use glam::{DVec3, UVec3, Vec3};

use crate::generate::block;
use crate::mesh::TetMesh;

use super::body::RheologyBody;
use super::error::RheologyError;
use super::material::RheologyMaterial;

/// Size and resolution of the block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Specimen {
    /// Edge lengths x, y, z, m; the block spans `[−x/2, x/2] × [−y/2, y/2] × [0, z]`.
    pub size: DVec3,
    /// Hex cells along x, y, z (6 tets each).
    pub cells: UVec3,
}

/// A specimen's mesh and the node sets the experiments use.
#[derive(Debug, Clone)]
pub struct SpecimenMesh {
    /// The block.
    pub mesh: TetMesh,
    /// Nodes on the table (z = 0), pinned.
    pub bottom: Vec<u32>,
    /// Nodes on the top face (z = height), the ones an indenter can touch.
    pub top: Vec<u32>,
    /// The node at the centre of the top face (where indentation depth is measured).
    pub top_centre: u32,
    /// Nodes in the vertical mid-plane y = 0 (a section through the indenter's centre and
    /// the middle of two side faces), drawn in side views.
    pub section: Vec<u32>,
    /// Nodes on the +x side face in the mid-plane, bottom to top (the side's bulge profile).
    pub side_profile: Vec<u32>,
}

impl Specimen {
    /// The press-and-release block: 30 × 30 × 15 cm in 6 × 6 × 3 cells (5 cm edges).
    pub fn standard() -> Self {
        Specimen {
            size: DVec3::new(0.3, 0.3, 0.15),
            cells: UVec3::new(6, 6, 3),
        }
    }

    /// The gravity block: 40 × 40 × 20 cm in 4 × 4 × 2 cells (10 cm edges). Coarse because
    /// the explicit step of a viscous body shrinks with the edge length squared (δ ∝ η/(ρL0²),
    /// see `stability.rs`) and a shape-keeping damper is very viscous.
    pub fn coarse() -> Self {
        Specimen {
            size: DVec3::new(0.4, 0.4, 0.2),
            cells: UVec3::new(4, 4, 2),
        }
    }

    /// Build the mesh and node sets.
    pub fn mesh(&self) -> Result<SpecimenMesh, RheologyError> {
        let min = Vec3::new(-0.5 * self.size.x as f32, -0.5 * self.size.y as f32, 0.0);
        let (mesh, _) = TetMesh::from_raw(block(min, self.size.as_vec3(), self.cells))?;
        let tol = 1e-6 * self.size.max_element();
        let pick = |keep: &dyn Fn(DVec3) -> bool| -> Vec<u32> {
            (0..mesh.node_count() as u32)
                .filter(|&i| keep(mesh.rest_positions[i as usize].as_dvec3()))
                .collect()
        };
        let bottom = pick(&|p| p.z < tol);
        let top = pick(&|p| p.z > self.size.z - tol);
        let section = pick(&|p| p.y.abs() < tol);
        let mut side_profile = pick(&|p| p.y.abs() < tol && p.x > 0.5 * self.size.x - tol);
        side_profile.sort_by(|&a, &b| {
            let z = |i: u32| mesh.rest_positions[i as usize].z;
            z(a).total_cmp(&z(b))
        });
        let centre = DVec3::new(0.0, 0.0, self.size.z);
        let top_centre = *top
            .iter()
            .min_by(|&&a, &&b| {
                let d = |i: u32| (mesh.rest_positions[i as usize].as_dvec3() - centre).length();
                d(a).total_cmp(&d(b))
            })
            .expect("a block has a top face");
        Ok(SpecimenMesh {
            mesh,
            bottom,
            top,
            top_centre,
            section,
            side_profile,
        })
    }
}

impl SpecimenMesh {
    /// A body of one material on the table (bottom nodes pinned), gravity `g` along −z.
    pub fn body(&self, material: RheologyMaterial, g: f64) -> Result<RheologyBody, RheologyError> {
        let mut body = RheologyBody::uniform(&self.mesh, material)?;
        body.pin(&self.bottom);
        body.set_gravity(DVec3::new(0.0, 0.0, -g));
        Ok(body)
    }

    /// Depth of the top centre below its rest height in `body`, m.
    pub fn centre_depth(&self, body: &RheologyBody) -> f64 {
        let i = self.top_centre as usize;
        self.mesh.rest_positions[i].z as f64 - body.position(i).z
    }
}
