//! A chest-scale test body for the loop-time measurements (PHYSICS.md §2.6: the paper's
//! chest wall + heart from MRI has 17,582 nodes and 73,279 tets).

use glam::{DVec3, UVec3, Vec3};

use crate::generate::block;
use crate::mass_spring::{AxisMask, MassSpringError, MassSpringModel, MassSpringParams, Tension};
use crate::mesh::TetMesh;

/// Size of the slab, m: 30 × 12.5 × 0.5 cm of 2.5 mm cubes.
pub const CHEST_SLAB_SIZE: [f64; 3] = [0.30, 0.125, 0.005];

/// A 30 × 12.5 × 0.5 cm slab of 120 × 50 × 2 Kuhn-split cubes: 18,513 nodes and 72,000
/// tets (the paper's chest: 17,582 / 73,279), under 4 % tension, its rim held, the
/// paper's k, b and ρ.
pub fn chest_slab_model() -> Result<MassSpringModel, MassSpringError> {
    let [sx, sy, sz] = CHEST_SLAB_SIZE;
    let raw = block(
        Vec3::new(-0.5 * sx as f32, -0.5 * sy as f32, 0.0),
        Vec3::new(sx as f32, sy as f32, sz as f32),
        UVec3::new(120, 50, 2),
    );
    let (mesh, _) = TetMesh::from_raw(raw).map_err(|e| MassSpringError::BadParameter {
        field: "mesh",
        msg: e.to_string(),
    })?;
    let mut m = MassSpringModel::new(
        &mesh,
        MassSpringParams {
            tension: Tension::Uniform(0.04),
            ..MassSpringParams::default()
        },
    )?;
    let rim: Vec<u32> = (0..m.node_count() as u32)
        .filter(|&i| {
            let p = m.positions()[i as usize];
            p.x.abs() > 0.5 * sx - 1e-6 || p.y.abs() > 0.5 * sy - 1e-6
        })
        .collect();
    m.fix(&rim, AxisMask::ALL)?;
    Ok(m)
}

/// Blade pose of a vertical blade through the slab at `(x, y)`.
pub fn slab_blade(x: f64, y: f64) -> super::BladePose {
    super::BladePose {
        heel: DVec3::new(x, y, -0.002),
        tip: DVec3::new(x, y, CHEST_SLAB_SIZE[2] + 0.002),
    }
}
