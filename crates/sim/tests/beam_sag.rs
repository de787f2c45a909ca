//! Validation test 3: a cantilever under gravity sags as Euler–Bernoulli predicts,
//! δ = ρgAL⁴/(8EI), once the substeps are enough, converging monotonically as they grow.
//!
//! XPBD with one iteration per substep behaves like the material with an added compliance
//! of order h²·k/m (Macklin et al. 2019), so the sag is too large at few substeps and falls
//! toward the exact value as the substep shrinks.

mod common;

use glam::{UVec3, Vec3};
use incise_sim::generate::beam;
use incise_sim::selection::NodeSelection;
use incise_sim::{Material, SolverParams, TetMesh};

const LEN: f32 = 0.2;
const H: f32 = 0.02;

fn tip_deflection(substeps: u32) -> f32 {
    let mesh = TetMesh::from_raw(beam(LEN, H, H, UVec3::new(20, 4, 4)))
        .unwrap()
        .0;
    // E and ρ chosen so that the static sag is 1 % of the length (small strain).
    let material = Material {
        youngs_modulus: 1.0e6,
        poisson_ratio: 0.3,
        density: 1000.0,
    };
    let params = SolverParams {
        substeps,
        damping: 15.0,
        threads: 1,
        ..SolverParams::default()
    };
    let mut s = common::solver(mesh, material, params);
    let rest = s.mesh().rest_positions.clone();
    let root = NodeSelection::PlaneSide {
        point: Vec3::new(1e-4, 0.0, 0.0),
        normal: -Vec3::X,
    };
    s.pin(&root.select(&rest).unwrap());
    let tip: Vec<u32> = NodeSelection::PlaneSide {
        point: Vec3::new(LEN - 1e-4, 0.0, 0.0),
        normal: Vec3::X,
    }
    .select(&rest)
    .unwrap();
    for _ in 0..120 {
        s.step_frame().unwrap();
    }
    let mean_dz: f32 = tip
        .iter()
        .map(|&i| s.positions()[i as usize].z - rest[i as usize].z)
        .sum::<f32>()
        / tip.len() as f32;
    -mean_dz
}

fn euler_bernoulli(m: &Material) -> f32 {
    let (a, i) = (H * H, H * H * H * H / 12.0);
    m.density * 9.81 * a * LEN.powi(4) / (8.0 * m.youngs_modulus * i)
}

#[test]
fn cantilever_sag_converges_to_euler_bernoulli() {
    let m = Material {
        youngs_modulus: 1.0e6,
        poisson_ratio: 0.3,
        density: 1000.0,
    };
    let exact = euler_bernoulli(&m);
    let series: Vec<(u32, f32)> = [25, 50, 100, 200]
        .iter()
        .map(|&n| (n, tip_deflection(n)))
        .collect();
    eprintln!("Euler–Bernoulli {exact:.5} m; XPBD {series:?}");
    for w in series.windows(2) {
        assert!(
            w[1].1 < w[0].1,
            "sag did not decrease from {:?} to {:?}",
            w[0],
            w[1]
        );
    }
    let (n, finest) = *series.last().unwrap();
    let err = (finest - exact).abs() / exact;
    assert!(
        err < 0.10,
        "{n} substeps: sag {finest} vs {exact} ({:.1} %)",
        err * 100.0
    );
}
