//! A tet as the implicit scheme's coarse level and Hessian product read it: its nodes,
//! inverse rest shape matrix and rest volume, copied out of the mesh once.

use glam::{Mat3, Vec3};

use crate::xpbd::{Strain, displacement_gradient};

/// One tet as the coarse assembly reads it.
#[derive(Debug, Clone, Copy)]
pub struct RestTet {
    /// Its four nodes.
    pub nodes: [u32; 4],
    /// Inverse rest shape matrix.
    pub dm_inv: Mat3,
    /// Rest volume, m³.
    pub volume: f32,
}

impl RestTet {
    /// Every tet of `mesh`, in mesh order.
    pub fn all(mesh: &crate::mesh::TetMesh) -> Vec<RestTet> {
        (0..mesh.tet_count())
            .map(|t| RestTet {
                nodes: mesh.tets[t],
                dm_inv: mesh.dm_inv[t],
                volume: mesh.rest_volume[t],
            })
            .collect()
    }

    /// Its strain at the nodes' displacements `u` (PHYSICS.md §1.2: `F = I + Du Dm⁻¹`).
    pub fn strain(&self, u: &[Vec3]) -> Strain {
        let du = self.nodes.map(|i| u[i as usize]);
        Strain::of(displacement_gradient(&du, &self.dm_inv))
    }
}
