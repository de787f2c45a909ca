//! Criterion benchmarks of one RK4 step of the three-element rheological body (PHYSICS.md
//! §3) with the `rheological` preset on the Nakao plate (3.5k tets) and the 34k-tet
//! intestine, against the plain mass-spring step on the same mesh:
//!
//! - `spring_rk4`: the same RK4 integrator, state layout and two force passes with a plain
//!   spring-damper edge `k(L − L0) + c L̇` (the "plain mass-spring step", integrated
//!   like the rheological body so that the ratio is the cost of the element law alone);
//! - `nakao_euler`: the Nakao mass-spring model's own step (`mass_spring`, one force
//!   evaluation per step instead of RK4's four).

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use incise_sim::generate::{IntestineParams, intestine, plate};
use incise_sim::mass_spring::{MassSpringModel, MassSpringParams};
use incise_sim::mesh::EdgeList;
use incise_sim::rheology::{RheologyBody, RheologyPresets, Rk4};
use incise_sim::{RawMesh, TetMesh};
use rayon::prelude::*;

/// Edge count from which the spring passes run on the rayon pool (as the body's).
const PARALLEL_EDGES: usize = 20_000;

/// A plain spring-damper network integrated with RK4: the comparison step.
struct SpringNetwork {
    edges: EdgeList,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    rest: Vec<f64>,
    masses: Vec<f64>,
    state: Vec<f64>,
    rk4: Rk4,
    edge_force: Vec<DVec3>,
}

impl SpringNetwork {
    /// Spring `k = stiffness·L0` and damper `c = viscosity·L0` per edge, like the presets.
    fn new(mesh: &TetMesh, stiffness: f64, viscosity: f64, density: f64) -> Self {
        let edges = EdgeList::of_mesh(mesh);
        let rest: Vec<f64> = edges.rest_length.iter().map(|&l| l as f64).collect();
        let n = mesh.node_count();
        let mut state = vec![0.0; 6 * n];
        for (i, p) in mesh.rest_positions.iter().enumerate() {
            p.as_dvec3().write_to_slice(&mut state[3 * i..3 * i + 3]);
        }
        SpringNetwork {
            stiffness: rest.iter().map(|l| stiffness * l).collect(),
            damping: rest.iter().map(|l| viscosity * l).collect(),
            masses: mesh
                .lumped_masses(density as f32)
                .iter()
                .map(|&m| m as f64)
                .collect(),
            rk4: Rk4::new(state.len()),
            edge_force: vec![DVec3::ZERO; edges.len()],
            state,
            rest,
            edges,
        }
    }

    fn step(&mut self, h: f64) {
        let SpringNetwork {
            edges,
            stiffness,
            damping,
            rest,
            masses,
            state,
            rk4,
            edge_force,
        } = self;
        let n = masses.len();
        rk4.step(state, 0.0, h, |_, y, dy| {
            let (x, v) = (&y[..3 * n], &y[3 * n..]);
            let edge = |e: usize, f: &mut DVec3| {
                let [i, j] = edges.edges[e];
                let (i, j) = (3 * i as usize, 3 * j as usize);
                let d = DVec3::from_slice(&x[j..j + 3]) - DVec3::from_slice(&x[i..i + 3]);
                let len = d.length();
                // One reciprocal, as the rheological body's edge pass does.
                let dir = d * (1.0 / len);
                let rate =
                    (DVec3::from_slice(&v[j..j + 3]) - DVec3::from_slice(&v[i..i + 3])).dot(dir);
                *f = dir * (stiffness[e] * (len - rest[e]) + damping[e] * rate);
            };
            let node = |i: usize, ef: &[DVec3], dx: &mut [f64], dv: &mut [f64]| {
                let mut f = DVec3::ZERO;
                for &e in edges.edges_of_node(i) {
                    let e = e as usize;
                    if edges.edges[e][0] as usize == i {
                        f += ef[e];
                    } else {
                        f -= ef[e];
                    }
                }
                dx.copy_from_slice(&v[3 * i..3 * i + 3]);
                (f / masses[i]).write_to_slice(dv);
            };
            let (dx, dv) = dy.split_at_mut(3 * n);
            if edges.len() >= PARALLEL_EDGES {
                edge_force
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(e, f)| edge(e, f));
                let ef = &*edge_force;
                dx.par_chunks_mut(3)
                    .zip(dv.par_chunks_mut(3))
                    .enumerate()
                    .for_each(|(i, (dx, dv))| node(i, ef, dx, dv));
            } else {
                edge_force
                    .iter_mut()
                    .enumerate()
                    .for_each(|(e, f)| edge(e, f));
                for (i, (dx, dv)) in dx.chunks_mut(3).zip(dv.chunks_mut(3)).enumerate() {
                    node(i, edge_force, dx, dv);
                }
            }
        });
    }
}

/// The bodies under test on one mesh.
struct Case {
    name: &'static str,
    body: RheologyBody,
    step: f64,
    springs: SpringNetwork,
    nakao: MassSpringModel,
    nakao_step: f64,
}

fn cases() -> Vec<Case> {
    let presets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/rheology.ron");
    let material = RheologyPresets::load(&presets)
        .expect("config/rheology.ron loads")
        .get("rheological")
        .expect("rheological preset");
    let meshes: [(&str, RawMesh); 2] = [
        ("plate", plate()),
        ("intestine", intestine(&IntestineParams::default()).0),
    ];
    meshes
        .into_iter()
        .map(|(name, raw)| {
            let mesh = TetMesh::from_raw(raw).expect("generated mesh is valid").0;
            let mut body = RheologyBody::uniform(&mesh, material).expect("valid preset");
            // A small velocity field so the elements are not all at rest.
            for i in 0..body.node_count() {
                let p = body.position(i);
                body.set_velocity(i, DVec3::new(p.y.sin(), p.z.cos(), p.x.sin()) * 1e-3);
            }
            let params = MassSpringParams {
                gravity: DVec3::ZERO,
                ..MassSpringParams::default()
            };
            let nakao = MassSpringModel::new(&mesh, params).expect("valid mass-spring model");
            Case {
                name,
                step: body.stability().safe_step(),
                body,
                springs: SpringNetwork::new(
                    &mesh,
                    material.stiffness,
                    material.voigt_viscosity,
                    material.density,
                ),
                nakao_step: nakao.stable_dt(),
                nakao,
            }
        })
        .collect()
}

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("rheology_step");
    g.sample_size(20);
    for mut case in cases() {
        let (h, dt) = (case.step, case.nakao_step);
        g.bench_function(format!("{}/three_element_rk4", case.name), |b| {
            b.iter(|| case.body.step(h).expect("stable step"))
        });
        g.bench_function(format!("{}/spring_rk4", case.name), |b| {
            b.iter(|| case.springs.step(h))
        });
        g.bench_function(format!("{}/nakao_euler", case.name), |b| {
            b.iter(|| case.nakao.step(dt))
        });
    }
    g.finish();
}

/// The three steps timed back to back in 80 rounds, minimum per step: a ratio that holds
/// on a shared, noisy machine where criterion's medians drift between runs.
fn interleaved_ratios(_: &mut Criterion) {
    for mut case in cases() {
        let reps = if case.name == "plate" { 40 } else { 5 };
        let mut best = [f64::MAX; 3];
        let time = |best: &mut f64, f: &mut dyn FnMut()| {
            let t = std::time::Instant::now();
            for _ in 0..reps {
                f();
            }
            *best = best.min(t.elapsed().as_secs_f64() / reps as f64);
        };
        for _ in 0..80 {
            time(&mut best[0], &mut || {
                case.body.step(case.step).expect("stable step")
            });
            time(&mut best[1], &mut || case.springs.step(case.step));
            time(&mut best[2], &mut || case.nakao.step(case.nakao_step));
        }
        println!(
            "{}: {} edges; min ms per step: three-element RK4 {:.3}, spring RK4 {:.3}, \
             Nakao Euler {:.3}; three-element / spring = {:.2}",
            case.name,
            case.body.edges().len(),
            1e3 * best[0],
            1e3 * best[1],
            1e3 * best[2],
            best[0] / best[1]
        );
    }
}

criterion_group!(benches, steps, interleaved_ratios);
criterion_main!(benches);
