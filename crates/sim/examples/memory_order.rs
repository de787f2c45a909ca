//! What the order of tets and nodes is worth to the XPBD sweep (docs/performance.md,
//! "Memory order"): the intestine as generated, with its tets listed at random, and with
//! its nodes and tets numbered at random, each stepped by a solver in mesh order and one
//! in lowest-node order (`incise_sim::xpbd::TetOrder`), samples of a few frames alternating
//! between them on one thread. Prints the thread CPU time a substep (min / median over the
//! samples), which a loaded machine disturbs less than wall time.
//!
//! `MEMORY_TETS=1100000 MEMORY_SAMPLES=5 [MEMORY_SWEEP=blocks] cargo run --release -p
//! incise-sim --example memory_order` (defaults: 34,176 tets, 8 samples, coloured).

use glam::Vec3;
use incise_sim::generate::{IntestineParams, intestine};
use incise_sim::xpbd::{CpuSweep, TetOrder, stiffness_number, substeps_needed};
use incise_sim::{Material, RawMesh, Solver, SolverParams, TetMesh};

/// The environment variable `name` parsed, or `default`.
fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A fixed xorshift stream, so every run shuffles alike.
struct Shuffle(u64);

impl Shuffle {
    /// `v` in a random order (Fisher–Yates).
    fn apply<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            v.swap(i, (self.0 % (i as u64 + 1)) as usize);
        }
    }
}

/// `raw` with its tets listed at random and, if `nodes`, its nodes numbered at random.
fn scrambled(raw: &RawMesh, nodes: bool) -> RawMesh {
    let mut rng = Shuffle(0x9e37_79b9_7f4a_7c15);
    let mut new_of: Vec<u32> = (0..raw.positions.len() as u32).collect();
    if nodes {
        rng.apply(&mut new_of);
    }
    let mut positions = vec![Vec3::ZERO; raw.positions.len()];
    for (old, &new) in new_of.iter().enumerate() {
        positions[new as usize] = raw.positions[old];
    }
    let mut tets: Vec<[u32; 4]> = (raw.tets.iter())
        .map(|t| t.map(|i| new_of[i as usize]))
        .collect();
    rng.apply(&mut tets);
    RawMesh {
        positions,
        tets,
        warnings: Vec::new(),
        boundary_faces: None,
    }
}

/// A soft intestine (E 3 kPa, so that a fine mesh is stable at about a hundred substeps)
/// pinned at both ends, with its tets stored in `order`.
fn solver(raw: &RawMesh, order: TetOrder, sweep: CpuSweep) -> Solver {
    let mesh = TetMesh::from_raw(raw.clone())
        .expect("a scrambled valid mesh")
        .0;
    let m = Material {
        youngs_modulus: 3e3,
        poisson_ratio: 0.45,
        density: 1040.0,
    };
    // A hundred substeps or more and one stress pass a frame, so the sweeps dominate.
    let mut p = SolverParams {
        threads: 1,
        cpu_sweep: sweep,
        substeps: 100,
        release_interval: None,
        ..SolverParams::default()
    };
    let w: Vec<f32> = (mesh.lumped_masses(m.density).iter())
        .map(|&x| 1.0 / x)
        .collect();
    let (kappa, _) = stiffness_number(&mesh, &w, m.lame(), p.substep());
    p.substeps = p.substeps.max(substeps_needed(kappa, p.substeps));
    let mut s = Solver::with_tet_order(mesh, m, p, order).expect("stable settings");
    let rest = s.mesh().rest_positions.clone();
    let ends: Vec<u32> = (0..rest.len() as u32)
        .filter(|&i| rest[i as usize].x.abs() > 0.118)
        .collect();
    s.pin(&ends);
    s
}

/// This thread's CPU time so far, ms.
fn thread_cpu_ms() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux");
    let ns: f64 = (stat.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("schedstat starts with the CPU time in ns");
    ns / 1e6
}

/// Thread CPU ms of `frames` frames of `s`.
fn time(s: &mut Solver, frames: usize) -> f64 {
    let t0 = thread_cpu_ms();
    for _ in 0..frames {
        s.step_frame().expect("a stable frame");
    }
    thread_cpu_ms() - t0
}

/// Min and median of `v`.
fn min_median(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[0], v[v.len() / 2])
}

fn main() {
    let tets = env("MEMORY_TETS", 34_176usize);
    let samples = env("MEMORY_SAMPLES", 8usize);
    let sweep = match env("MEMORY_SWEEP", String::from("coloured")).as_str() {
        "blocks" => CpuSweep::Blocks,
        _ => CpuSweep::Coloured,
    };
    let generated = intestine(&IntestineParams::with_target_tets(tets)).0;
    let orders = [TetOrder::Mesh, TetOrder::Nodes];
    println!("| intestine, {sweep:?} | tets | substeps | mesh order | lowest node |");
    println!("|---|---|---|---|---|");
    for (name, raw) in [
        ("generated", generated.clone()),
        ("tets listed at random", scrambled(&generated, false)),
        ("nodes and tets at random", scrambled(&generated, true)),
    ] {
        let mut solvers: Vec<Solver> = orders.iter().map(|&o| solver(&raw, o, sweep)).collect();
        // A first frame each warms the caches and sizes a sample: enough frames for
        // 250 ms, far above the CPU clock's few-ms steps.
        let first = (solvers.iter_mut()).map(|s| time(s, 1)).fold(0.0, f64::max);
        let per_sample = (250.0 / first).ceil().max(1.0) as usize;
        let mut ms = vec![Vec::new(); orders.len()];
        for _ in 0..samples {
            for (s, ms) in solvers.iter_mut().zip(&mut ms) {
                let substeps = (per_sample as u32 * s.params().substeps) as f64;
                ms.push(time(s, per_sample) / substeps);
            }
        }
        let cells: Vec<String> = (ms.into_iter())
            .map(min_median)
            .map(|(min, med)| format!("{min:.3} / {med:.3}"))
            .collect();
        println!(
            "| {name} | {} | {} | {} |",
            solvers[0].mesh().tet_count(),
            solvers[0].params().substeps,
            cells.join(" | ")
        );
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("\nThread CPU ms a substep, min / median of {samples} samples; load average {load}");
}
