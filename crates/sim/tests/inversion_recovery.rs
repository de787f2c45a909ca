//! Validation test 5: Neo-Hookean inversion robustness — a mesh with every tet flattened
//! or inverted returns to its rest shape.

mod common;

use common::{block_mesh, soft, solver};
use glam::{Mat3, UVec3, Vec3};
use incise_sim::SolverParams;
use incise_sim::xpbd::deformation_gradient;

fn recover(deform: impl Fn(Vec3) -> Vec3) -> (usize, f32) {
    let mesh = block_mesh(Vec3::ZERO, Vec3::new(0.03, 0.03, 0.03), UVec3::new(3, 3, 3));
    let start: Vec<Vec3> = mesh.rest_positions.iter().map(|&p| deform(p)).collect();
    let params = SolverParams {
        gravity: Vec3::ZERO,
        damping: 5.0,
        threads: 1,
        max_inverted_frames: 120,
        ..SolverParams::default()
    };
    let mut s = solver(mesh, soft(20e3, 0.4), params);
    s.set_positions(&start);
    for _ in 0..180 {
        s.step_frame().unwrap();
    }
    let m = s.mesh();
    let mut inverted = 0;
    let mut worst_strain = 0.0f32;
    for (t, tet) in m.tets.iter().enumerate() {
        let x = tet.map(|i| s.positions()[i as usize]);
        let f = deformation_gradient(&x, &m.dm_inv[t]);
        if f.determinant() <= 0.0 {
            inverted += 1;
        }
        // Green strain E = (FᵀF − I)/2 is zero for any rigid placement of the rest shape.
        let e = (f.transpose() * f - Mat3::IDENTITY) * 0.5;
        let norm =
            (e.x_axis.length_squared() + e.y_axis.length_squared() + e.z_axis.length_squared())
                .sqrt();
        worst_strain = worst_strain.max(norm);
    }
    (inverted, worst_strain)
}

#[test]
fn flattened_block_recovers_its_rest_shape() {
    // Every node squashed onto z = 0.5 mm·(z/3 cm): each tet has ~1/60 of its volume.
    let (inverted, strain) = recover(|p| Vec3::new(p.x, p.y, p.z / 60.0));
    assert_eq!(inverted, 0);
    assert!(
        strain < 0.02,
        "largest Green strain after recovery: {strain}"
    );
}

#[test]
fn mirrored_block_with_every_tet_inverted_recovers() {
    let (inverted, strain) = recover(|p| Vec3::new(p.x, p.y, -p.z));
    assert_eq!(inverted, 0);
    assert!(
        strain < 0.02,
        "largest Green strain after recovery: {strain}"
    );
}
