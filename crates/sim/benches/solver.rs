//! Criterion benchmarks of one solver frame (all substeps, stress, release) on the Nakao
//! plate and the 34k-tet intestine, serial and with all threads.

use criterion::{Criterion, criterion_group, criterion_main};
use incise_sim::generate::{IntestineParams, intestine, plate};
use incise_sim::xpbd::{stiffness_number, substeps_needed};
use incise_sim::{Material, RawMesh, Solver, SolverParams, TetMesh};

fn solver(raw: RawMesh, threads: usize) -> Solver {
    let mesh = TetMesh::from_raw(raw).expect("generated mesh is valid").0;
    let m = Material {
        youngs_modulus: 180e3,
        poisson_ratio: 0.45,
        density: 1040.0,
    };
    let mut p = SolverParams {
        threads,
        ..SolverParams::default()
    };
    let w: Vec<f32> = mesh
        .lumped_masses(m.density)
        .iter()
        .map(|&x| 1.0 / x)
        .collect();
    let (kappa, _) = stiffness_number(&mesh, &w, m.lame(), p.substep());
    p.substeps = p.substeps.max(substeps_needed(kappa, p.substeps));
    Solver::new(mesh, m, p).expect("stable settings")
}

fn frames(c: &mut Criterion) {
    let mut g = c.benchmark_group("frame");
    g.sample_size(10);
    for (name, raw) in [
        ("plate", plate()),
        ("intestine", intestine(&IntestineParams::default()).0),
    ] {
        for threads in [1, 0] {
            let mut s = solver(raw.clone(), threads);
            let label = format!(
                "{name}/{}substeps/{}",
                s.params().substeps,
                if threads == 1 {
                    "serial"
                } else {
                    "all-threads"
                }
            );
            g.bench_function(label, |b| b.iter(|| s.step_frame().expect("frame")));
        }
    }
    g.finish();
}

/// Contact + SDF cost of one substep (issue 5 benchmark): every node of the 34k intestine
/// against a 32-sphere blade (plus its flat) pressed into the top of the wall, moving.
fn contact(c: &mut Criterion) {
    use glam::{Quat, Vec3};
    use incise_sim::contact::{
        ContactTool, PlacedTool, ToolBox, ToolPose, ToolSphere, project_node,
    };
    let mesh = TetMesh::from_raw(intestine(&IntestineParams::default()).0)
        .expect("generated mesh is valid")
        .0;
    let r = 0.5 * mesh.mean_edge_length();
    let tool = ContactTool {
        spheres: (0..32)
            .map(|i| ToolSphere {
                centre: Vec3::new(i as f32 * r, 0.0, 0.0),
                radius: r,
                cutting: true,
            })
            .collect(),
        boxes: vec![ToolBox {
            centre: Vec3::new(16.0 * r, 0.0, r + 0.005),
            rotation: Quat::IDENTITY,
            half_extents: Vec3::new(16.0 * r, 0.0002, 0.005),
        }],
        friction: 0.15,
    };
    let top = mesh
        .rest_positions
        .iter()
        .map(|p| p.z)
        .fold(f32::MIN, f32::max);
    let at = |x: f32| {
        PlacedTool::new(
            &tool,
            &ToolPose::new(Vec3::new(x, 0.0, top + r - 0.002), Quat::IDENTITY),
        )
    };
    let (from, to) = (at(-0.02), at(-0.0199));
    let x = mesh.rest_positions.clone();
    let mut g = c.benchmark_group("contact");
    g.bench_function("intestine/32spheres/one-substep", |b| {
        b.iter(|| {
            let mut moved = 0usize;
            for p in &x {
                moved += project_node(*p, *p, &from, &to, 0.15, Some(0.0005)).moved as usize;
            }
            moved
        })
    });
    g.finish();
}

criterion_group!(benches, frames, contact);
criterion_main!(benches);
