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

criterion_group!(benches, frames);
criterion_main!(benches);
