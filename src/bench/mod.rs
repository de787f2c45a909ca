//! `incise bench`: ms per substep and per frame (10 substeps) for the Nakao plate and the
//! 34k-tet intestine, serial and with all threads on the CPU, or on the GPU; optionally
//! the intestine scaling series (≈34k, 140k, 550k, 1.1M tets); plus memory.

pub mod peak;
pub mod realtime;
pub mod render;
pub mod scene;
pub mod soak;

use std::time::Instant;

use anyhow::Result;
use clap::ValueEnum;
use incise_sim::generate::{self, IntestineParams};
use incise_sim::selection::NodeSelection;
use incise_sim::xpbd::{stiffness_number, substeps_needed};
use incise_sim::{Material, RawMesh, Solver, SolverParams, TetMesh};
use serde::Serialize;

use crate::sim_body::{Body, DeviceChoice};

/// Benchmark case selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BenchCase {
    /// Plate and intestine.
    All,
    /// The Nakao plate.
    Plate,
    /// The 34k-tet intestine.
    Intestine,
}

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

/// How `incise bench` prints its results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BenchOutput {
    /// An aligned text table.
    Table,
    /// One JSON object.
    Json,
    /// The rows of docs/performance.md's CPU solver table, under a header naming the
    /// command, machine, date and load average.
    Markdown,
}

impl BenchOutput {
    /// The form the `--json` and `--markdown` flags ask for.
    pub fn of(json: bool, markdown: bool) -> Self {
        match (json, markdown) {
            (true, _) => BenchOutput::Json,
            (_, true) => BenchOutput::Markdown,
            _ => BenchOutput::Table,
        }
    }
}

/// Run the benchmark and print its results in `output`'s form.
pub fn run(
    case: BenchCase,
    frames: u32,
    output: BenchOutput,
    device: DeviceChoice,
    scaling: bool,
) -> Result<()> {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut results = Vec::new();
    for (name, raw) in cases(case, scaling) {
        let (mesh, _) = TetMesh::from_raw(raw)?;
        let configs: Vec<(usize, DeviceChoice)> = match device {
            DeviceChoice::Cpu if all > 1 => vec![(1, DeviceChoice::Cpu), (all, DeviceChoice::Cpu)],
            d => vec![(1, d)],
        };
        let mut variants = configs
            .into_iter()
            .map(|(threads, d)| Variant::new(&name, mesh.clone(), threads, d))
            .collect::<Result<Vec<_>>>()?;
        for r in time_interleaved(&mut variants, frames)? {
            if output == BenchOutput::Table {
                print_row(&r, results.is_empty());
            }
            results.push(r);
        }
    }
    let report = BenchReport {
        machine: crate::provenance::machine(),
        results,
    };
    match output {
        BenchOutput::Json => println!("{}", serde_json::to_string_pretty(&report)?),
        BenchOutput::Table => println!("machine: {}", report.machine),
        BenchOutput::Markdown => print!("{}", markdown(&report.results, frames)),
    }
    Ok(())
}

/// The meshes of `case`, and the scaling series with `scaling`.
fn cases(case: BenchCase, scaling: bool) -> Vec<(String, RawMesh)> {
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
    cases
}

/// One configuration to time (a mesh on a device with a thread count), warmed up, and
/// the samples taken so far.
struct Variant {
    result: BenchResult,
    body: Body,
    solve: Vec<f64>,
    frame: Vec<f64>,
    stress: Vec<f64>,
    gpu: Vec<f64>,
}

impl Variant {
    /// A body hanging from one end under gravity, 10 substeps per frame, after 2 warm-up
    /// frames.
    fn new(name: &str, mesh: TetMesh, threads: usize, device: DeviceChoice) -> Result<Self> {
        let params = SolverParams {
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
        let result = BenchResult {
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
            ms_per_substep_median: 0.0,
            ms_per_substep_min: 0.0,
            ms_per_frame_median: 0.0,
            gpu_ms_per_frame_median: None,
            stress_ms_median: 0.0,
            peak_mib: 0.0,
        };
        Ok(Variant {
            result,
            body,
            solve: Vec::new(),
            frame: Vec::new(),
            stress: Vec::new(),
            gpu: Vec::new(),
        })
    }

    /// Time one frame.
    fn sample(&mut self) -> Result<()> {
        let t = Instant::now();
        let s = self.body.step_frame()?;
        self.frame.push(t.elapsed().as_secs_f64() * 1e3);
        self.solve.push(s.solve_ms / s.substeps as f64);
        self.stress.push(s.stress_ms);
        if let Some(g) = self.body.gpu_frame_ms() {
            self.gpu.push(g);
        }
        Ok(())
    }

    /// The result with its medians and minimum.
    fn finish(mut self) -> BenchResult {
        let mut r = self.result;
        r.ms_per_substep_median = median(&mut self.solve);
        r.ms_per_substep_min = self.solve.iter().copied().fold(f64::INFINITY, f64::min);
        r.ms_per_frame_median = median(&mut self.frame);
        r.gpu_ms_per_frame_median = (!self.gpu.is_empty()).then(|| median(&mut self.gpu));
        r.stress_ms_median = median(&mut self.stress);
        r.peak_mib = peak_mib();
        r
    }
}

/// Time `frames` frames of every variant, interleaved frame by frame (variant 1, 2, 1,
/// 2, …) so that a change of the machine's load falls on all of them alike.
fn time_interleaved(variants: &mut Vec<Variant>, frames: u32) -> Result<Vec<BenchResult>> {
    for _ in 0..frames.max(1) {
        for v in variants.iter_mut() {
            v.sample()?;
        }
    }
    Ok(variants.drain(..).map(Variant::finish).collect())
}

/// The results as docs/performance.md's CPU solver table, under a header saying how,
/// where and when they were measured.
pub fn markdown(results: &[BenchResult], frames: u32) -> String {
    let p = crate::provenance::provenance();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut s = format!(
        "{MARKDOWN_HEADER} {}`: release build; frames of {BENCH_SUBSTEPS} substeps, the \
         small-bowel material softened to the {BENCH_SUBSTEPS}-substep stability bound, the \
         body hanging from one end under gravity; {frames} frames per variant after 2 \
         warm-up, the variants interleaved frame by frame; {}, {}, load average {}.\n\n\
         | case | tets | nodes | colours | threads | ms / substep (median) | min | ms / frame ({BENCH_SUBSTEPS} substeps) | stress pass ms / frame | peak MiB (process) |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        args.get(1..).unwrap_or_default().join(" "),
        p.machine,
        p.date_utc,
        p.load_average
    );
    for r in results {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.2} | {:.2} | {:.1} |\n",
            r.case,
            thousands(r.tets),
            thousands(r.nodes),
            r.colors,
            r.threads,
            r.ms_per_substep_median,
            r.ms_per_substep_min,
            r.ms_per_frame_median,
            r.stress_ms_median,
            r.peak_mib
        ));
    }
    s
}

/// How every `--markdown` table begins, followed by the rest of the command line and
/// where and when it ran (tests/docs_figures.rs looks for it).
pub const MARKDOWN_HEADER: &str = "Generated by `incise bench";

/// `n` with thousands separated by commas (34,176).
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
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
