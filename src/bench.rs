//! `incise bench`: ms per substep and per frame (10 substeps) for the Nakao plate and the
//! 34k-tet intestine, serial and with all threads on the CPU, or on the GPU; optionally
//! the intestine scaling series (≈34k, 140k, 550k, 1.1M tets); plus memory.

use std::time::Instant;

use anyhow::Result;
use incise_sim::generate::{self, IntestineParams};
use incise_sim::selection::NodeSelection;
use incise_sim::xpbd::{stiffness_number, substeps_needed};
use incise_sim::{Material, RawMesh, Solver, SolverParams, TetMesh};
use serde::Serialize;

use crate::body::{Body, DeviceChoice};
use crate::cli::BenchCase;

/// Substeps per benchmark frame.
pub const BENCH_SUBSTEPS: u32 = 10;

/// Small-bowel tissue (config/materials.ron "small_intestine").
const BOWEL: Material = Material {
    youngs_modulus: 180e3,
    poisson_ratio: 0.45,
    density: 1040.0,
};

/// One timed configuration.
#[derive(Debug, Clone, Serialize)]
pub struct BenchResult {
    /// Case name.
    pub case: String,
    /// Tets.
    pub tets: usize,
    /// Nodes.
    pub nodes: usize,
    /// Colours (parallel passes per substep).
    pub colors: usize,
    /// Worker threads (CPU) or 0 (GPU).
    pub threads: usize,
    /// "cpu" or the GPU adapter.
    pub device: String,
    /// Substeps per frame (always 10).
    pub substeps: u32,
    /// Young's modulus simulated, Pa: small bowel, softened to the stability bound at 10
    /// substeps where the mesh needs it (the cost does not depend on it).
    pub youngs_modulus: f32,
    /// Substeps per 60 Hz frame that small-bowel stiffness would need on this mesh.
    pub bowel_substeps_needed: u32,
    /// Median ms per substep (wall time of the frame's substeps / 10; on the GPU this
    /// includes the per-frame readback).
    pub ms_per_substep_median: f64,
    /// Fastest ms per substep.
    pub ms_per_substep_min: f64,
    /// Median wall ms per frame (substeps + stress + release + readback).
    pub ms_per_frame_median: f64,
    /// Median GPU kernel ms per frame (timestamps), when available.
    pub gpu_ms_per_frame_median: Option<f64>,
    /// Median ms of the per-frame stress/guard/release work on the host.
    pub stress_ms_median: f64,
    /// Peak resident memory of the process so far, MiB.
    pub peak_mib: f64,
}

/// Whole benchmark output.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// CPU model and core count.
    pub machine: String,
    /// Results.
    pub results: Vec<BenchResult>,
}

/// Run the benchmark and print a table or one JSON object.
pub fn run(
    case: BenchCase,
    frames: u32,
    json: bool,
    device: DeviceChoice,
    scaling: bool,
) -> Result<()> {
    let mut cases: Vec<(String, RawMesh)> = Vec::new();
    if matches!(case, BenchCase::All | BenchCase::Plate) {
        cases.push(("plate".into(), generate::plate()));
    }
    if matches!(case, BenchCase::All | BenchCase::Intestine) {
        cases.push((
            "intestine".into(),
            generate::intestine(&IntestineParams::default()).0,
        ));
    }
    if scaling {
        for n in [140_000, 550_000, 1_100_000] {
            let p = IntestineParams::with_target_tets(n);
            cases.push((
                format!("intestine-{}k", p.tet_count() / 1000),
                generate::intestine(&p).0,
            ));
        }
    }
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut results = Vec::new();
    for (name, raw) in cases {
        let (mesh, _) = TetMesh::from_raw(raw)?;
        let configs: Vec<(usize, DeviceChoice)> = match device {
            DeviceChoice::Cpu => {
                let mut t = vec![(1, DeviceChoice::Cpu)];
                if all > 1 {
                    t.push((all, DeviceChoice::Cpu));
                }
                t
            }
            d => vec![(1, d)],
        };
        for (threads, d) in configs {
            let r = time_case(&name, mesh.clone(), threads, d, frames)?;
            if !json {
                print_row(&r, results.is_empty());
            }
            results.push(r);
        }
    }
    let report = BenchReport {
        machine: machine(),
        results,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("machine: {}", report.machine);
    }
    Ok(())
}

/// Time `frames` frames (10 substeps each) of a body hanging from one end under gravity,
/// after 2 warm-up frames.
fn time_case(
    name: &str,
    mesh: TetMesh,
    threads: usize,
    device: DeviceChoice,
    frames: u32,
) -> Result<BenchResult> {
    let mut params = SolverParams {
        threads,
        substeps: BENCH_SUBSTEPS,
        ..SolverParams::default()
    };
    let w: Vec<f32> = mesh
        .lumped_masses(BOWEL.density)
        .iter()
        .map(|&m| 1.0 / m)
        .collect();
    let (kappa, _) = stiffness_number(&mesh, &w, BOWEL.lame(), params.substep());
    // κ ∝ E: soften just enough (2 % margin) for 10 substeps to be stable.
    let material = Material {
        youngs_modulus: BOWEL.youngs_modulus * (0.98 / kappa).min(1.0),
        ..BOWEL
    };
    params.substeps = BENCH_SUBSTEPS;
    let (lo, hi) = mesh.rest_bounds();
    let (tets, nodes) = (mesh.tet_count(), mesh.node_count());
    let mut solver = Solver::new(mesh, material, params)?;
    let rest = solver.mesh().rest_positions.clone();
    let pins = NodeSelection::PlaneSide {
        point: lo + (hi - lo) * 0.05,
        normal: -glam::Vec3::X,
    }
    .select(&rest)?;
    solver.pin(&pins);
    let colors = solver.color_count();
    let mut body = Body::place(solver, device, |m| eprintln!("note: {m}"))?;
    for _ in 0..2 {
        body.step_frame()?;
    }
    let (mut solve, mut frame, mut stress, mut gpu) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..frames.max(1) {
        let t = Instant::now();
        let s = body.step_frame()?;
        frame.push(t.elapsed().as_secs_f64() * 1e3);
        solve.push(s.solve_ms / s.substeps as f64);
        stress.push(s.stress_ms);
        if let Some(g) = body.gpu_frame_ms() {
            gpu.push(g);
        }
    }
    Ok(BenchResult {
        case: name.into(),
        tets,
        nodes,
        colors,
        threads: if matches!(body, Body::Gpu(_)) {
            0
        } else {
            threads
        },
        device: body.device(),
        substeps: BENCH_SUBSTEPS,
        youngs_modulus: material.youngs_modulus,
        bowel_substeps_needed: substeps_needed(kappa, BENCH_SUBSTEPS).max(BENCH_SUBSTEPS),
        ms_per_substep_median: median(&mut solve),
        ms_per_substep_min: solve.iter().copied().fold(f64::INFINITY, f64::min),
        ms_per_frame_median: median(&mut frame),
        gpu_ms_per_frame_median: (!gpu.is_empty()).then(|| median(&mut gpu)),
        stress_ms_median: median(&mut stress),
        peak_mib: peak_mib(),
    })
}

fn print_row(r: &BenchResult, header: bool) {
    if header {
        println!(
            "{:<16} {:>8} {:>7} {:>4} {:>4} {:>11} {:>8} {:>9} {:>9} {:>8} {:>8}  device",
            "case",
            "tets",
            "nodes",
            "col",
            "thr",
            "ms/substep",
            "min",
            "ms/frame",
            "gpu ms",
            "host ms",
            "peakMiB"
        );
    }
    let gpu = r
        .gpu_ms_per_frame_median
        .map_or("-".into(), |g| format!("{g:.3}"));
    println!(
        "{:<16} {:>8} {:>7} {:>4} {:>4} {:>11.3} {:>8.3} {:>9.2} {:>9} {:>8.2} {:>8.1}  {}",
        r.case,
        r.tets,
        r.nodes,
        r.colors,
        r.threads,
        r.ms_per_substep_median,
        r.ms_per_substep_min,
        r.ms_per_frame_median,
        gpu,
        r.stress_ms_median,
        r.peak_mib,
        r.device
    );
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Peak resident set size (VmHWM) in MiB; 0 where /proc is unavailable.
fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// CPU model name and logical core count.
pub fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{model}, {cores} logical cores")
}
