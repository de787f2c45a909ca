//! `incise experiment nakao-bench`: loop times of the Nakao mass-spring cutter on a
//! chest-scale slab (18.5k nodes, 72k tets; the paper's chest: 17.6k / 73k) — the whole
//! mesh, localised loops at levels 4 and 6 along a scripted cut, the refresh-rate manager
//! at a budget, and the blade advances themselves.

use std::time::Instant;

use anyhow::Result;
use glam::DVec3;
use incise_sim::mass_spring::{LocalLoop, LocalLoopParams, MassSpringModel, SystemClock};
use incise_sim::nakao_cut::{CutParams, Cutter, chest_slab_model, slab_blade};
use serde::Serialize;

/// Options of the benchmark.
#[derive(Debug, Clone)]
pub struct NakaoBenchOptions {
    /// Loops per case.
    pub loops: usize,
    /// Budget of the refresh-rate manager case, ms.
    pub budget_ms: f64,
    /// Print JSON instead of a table.
    pub json: bool,
}

/// Timing of one case.
#[derive(Debug, Clone, Serialize)]
pub struct LoopTiming {
    /// Case name.
    pub case: String,
    /// Median loop time, ms.
    pub median_ms: f64,
    /// Fastest loop, ms.
    pub min_ms: f64,
    /// Slowest loop, ms.
    pub max_ms: f64,
    /// Fewest free nodes in a loop.
    pub free_min: usize,
    /// Most free nodes in a loop.
    pub free_max: usize,
    /// Share of loops within ±15 % of the budget (manager case only).
    pub within_15_percent: Option<f64>,
}

/// The whole output.
#[derive(Debug, Clone, Serialize)]
pub struct NakaoBench {
    /// CPU and cores.
    pub machine: String,
    /// Nodes and tets of the slab.
    pub mesh: (usize, usize),
    /// Cases.
    pub results: Vec<LoopTiming>,
}

fn summary(case: &str, ms: &mut [f64], free: &[usize], budget: Option<f64>) -> LoopTiming {
    ms.sort_by(f64::total_cmp);
    LoopTiming {
        case: case.into(),
        median_ms: ms[ms.len() / 2],
        min_ms: ms[0],
        max_ms: ms[ms.len() - 1],
        free_min: free.iter().copied().min().unwrap_or(0),
        free_max: free.iter().copied().max().unwrap_or(0),
        within_15_percent: budget.map(|b| {
            ms.iter().filter(|&&t| (t - b).abs() <= 0.15 * b).count() as f64 / ms.len() as f64
        }),
    }
}

/// The scripted stroke: the tool moves 0.2 mm per loop along the slab's middle; the blade
/// advances (cuts) every 10 loops.
fn stroke(
    model: &mut MassSpringModel,
    params: LocalLoopParams,
    loops: usize,
    cut_ms: &mut Vec<f64>,
) -> (Vec<f64>, Vec<usize>) {
    let mut local = LocalLoop::new(params, SystemClock::default());
    let mut cutter = Cutter::new(CutParams::default());
    let y = 0.0013;
    let x0 = -0.1;
    cutter.begin(model, slab_blade(x0, y));
    let dt = model.stable_dt();
    let (mut ms, mut free) = (Vec::with_capacity(loops), Vec::with_capacity(loops));
    for k in 1..=loops {
        let x = x0 + 0.0002 * k as f64;
        if k % 10 == 0 {
            let r = cutter.advance(model, slab_blade(x, y));
            cut_ms.push(r.ms);
        }
        let t = Instant::now();
        let s = local.step(model, DVec3::new(x, y, 0.005), dt);
        ms.push(t.elapsed().as_secs_f64() * 1e3);
        free.push(s.free_nodes);
    }
    (ms, free)
}

/// Run the cases and print a table (or JSON).
pub fn run(opts: &NakaoBenchOptions) -> Result<()> {
    let base = chest_slab_model()?;
    let mesh = (base.node_count(), base.tet_count());
    let loops = opts.loops.max(10);
    let mut results = Vec::new();
    let mut cut_ms = Vec::new();
    for level in [4, 6] {
        let mut m = base.clone();
        let params = LocalLoopParams {
            max_level: level,
            ..LocalLoopParams::default()
        };
        let (mut ms, free) = stroke(&mut m, params, loops, &mut cut_ms);
        results.push(summary(&format!("level {level}"), &mut ms, &free, None));
    }
    {
        let mut m = base.clone();
        let params = LocalLoopParams {
            budget_ms: Some(opts.budget_ms),
            max_level: u32::MAX,
            ..LocalLoopParams::default()
        };
        let (mut ms, free) = stroke(&mut m, params, loops, &mut Vec::new());
        // Skip the first 20 loops: the manager starts from a small set and converges.
        let skip = 20.min(ms.len() / 2);
        results.push(summary(
            &format!("manager, budget {} ms", opts.budget_ms),
            &mut ms[skip..],
            &free[skip..],
            Some(opts.budget_ms),
        ));
    }
    {
        let mut m = base.clone();
        let dt = m.stable_dt();
        let mut ms = Vec::new();
        for _ in 0..loops.min(200) {
            let t = Instant::now();
            m.step(dt);
            ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        results.push(summary("full mesh", &mut ms, &[mesh.0], None));
    }
    results.push(summary("blade advance (cut)", &mut cut_ms, &[], None));
    let report = NakaoBench {
        machine: crate::provenance::machine(),
        mesh,
        results,
    };
    if opts.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("machine: {}", report.machine);
        println!("mesh: {} nodes, {} tets", mesh.0, mesh.1);
        println!(
            "{:<26} {:>10} {:>10} {:>10} {:>14} {:>10}",
            "case", "median ms", "min ms", "max ms", "free nodes", "±15 %"
        );
        for r in &report.results {
            println!(
                "{:<26} {:>10.4} {:>10.4} {:>10.4} {:>6}–{:<7} {:>10}",
                r.case,
                r.median_ms,
                r.min_ms,
                r.max_ms,
                r.free_min,
                r.free_max,
                r.within_15_percent
                    .map_or("-".to_string(), |w| format!("{:.0} %", w * 100.0))
            );
        }
    }
    Ok(())
}
