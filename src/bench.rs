//! `incise bench`: ms per substep and per frame for the plate and the 34k-tet intestine,
//! serial and with all threads, plus peak memory.

use std::time::Instant;

use anyhow::Result;
use incise_sim::generate::{self, IntestineParams};
use incise_sim::selection::NodeSelection;
use incise_sim::xpbd::{stiffness_number, substeps_needed};
use incise_sim::{Material, RawMesh, Solver, SolverParams, TetMesh};
use serde::Serialize;

use crate::cli::BenchCase;

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
    /// Worker threads.
    pub threads: usize,
    /// Device.
    pub device: String,
    /// Substeps per frame.
    pub substeps: u32,
    /// Median ms per substep (substep loop only).
    pub ms_per_substep_median: f64,
    /// Fastest ms per substep.
    pub ms_per_substep_min: f64,
    /// Median ms per frame (substeps + stress + release).
    pub ms_per_frame_median: f64,
    /// Median ms of the per-frame stress/guard/release pass.
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
pub fn run(case: BenchCase, frames: u32, json: bool) -> Result<()> {
    let mut cases: Vec<(&str, RawMesh)> = Vec::new();
    if matches!(case, BenchCase::All | BenchCase::Plate) {
        cases.push(("plate", generate::plate()));
    }
    if matches!(case, BenchCase::All | BenchCase::Intestine) {
        cases.push((
            "intestine",
            generate::intestine(&IntestineParams::default()).0,
        ));
    }
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut thread_counts = vec![1];
    if all > 1 {
        thread_counts.push(all);
    }
    let mut results = Vec::new();
    for (name, raw) in cases {
        let (mesh, _) = TetMesh::from_raw(raw)?;
        for &threads in &thread_counts {
            let r = time_case(name, mesh.clone(), threads, frames)?;
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

/// Time `frames` frames of a body of small-bowel tissue (E = 180 kPa, ν = 0.45) hanging from
/// one end under gravity (after 2 warm-up frames).
fn time_case(name: &str, mesh: TetMesh, threads: usize, frames: u32) -> Result<BenchResult> {
    let material = Material {
        youngs_modulus: 180e3,
        poisson_ratio: 0.45,
        density: 1040.0,
    };
    // The substep count is the fewest the stability bound allows for this tissue and mesh
    // (incise_sim::xpbd::stability); ms per substep does not depend on it.
    let mut params = SolverParams {
        threads,
        ..SolverParams::default()
    };
    let w: Vec<f32> = mesh
        .lumped_masses(material.density)
        .iter()
        .map(|&m| 1.0 / m)
        .collect();
    let (kappa, _) = stiffness_number(&mesh, &w, material.lame(), params.substep());
    params.substeps = params.substeps.max(substeps_needed(kappa, params.substeps));
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
    for _ in 0..2 {
        solver.step_frame()?;
    }
    let mut solve = Vec::new();
    let mut frame = Vec::new();
    let mut stress = Vec::new();
    for _ in 0..frames.max(1) {
        let t = Instant::now();
        let s = solver.step_frame()?;
        frame.push(t.elapsed().as_secs_f64() * 1e3);
        solve.push(s.solve_ms / s.substeps as f64);
        stress.push(s.stress_ms);
    }
    Ok(BenchResult {
        case: name.into(),
        tets,
        nodes,
        colors: solver.color_count(),
        threads,
        device: "cpu".into(),
        substeps: solver.params().substeps,
        ms_per_substep_median: median(&mut solve),
        ms_per_substep_min: solve.iter().copied().fold(f64::INFINITY, f64::min),
        ms_per_frame_median: median(&mut frame),
        stress_ms_median: median(&mut stress),
        peak_mib: peak_mib(),
    })
}

fn print_row(r: &BenchResult, header: bool) {
    if header {
        println!(
            "{:<10} {:>7} {:>6} {:>7} {:>4} {:>12} {:>10} {:>11} {:>10} {:>8}",
            "case",
            "tets",
            "nodes",
            "colours",
            "thr",
            "ms/substep",
            "min",
            "ms/frame",
            "stress ms",
            "peak MiB"
        );
    }
    println!(
        "{:<10} {:>7} {:>6} {:>7} {:>4} {:>12.3} {:>10.3} {:>11.2} {:>10.2} {:>8.1}",
        r.case,
        r.tets,
        r.nodes,
        r.colors,
        r.threads,
        r.ms_per_substep_median,
        r.ms_per_substep_min,
        r.ms_per_frame_median,
        r.stress_ms_median,
        r.peak_mib
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
fn machine() -> String {
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
