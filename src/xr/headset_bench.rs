//! The headset figures of `incise bench realtime --markdown` (issue 31, item 3), printed
//! under its table (here, above the benchmark's layer, as the headset's own): the scene
//! in a simulated Quest 3 on the wall clock (72 Hz, the simulation on its own thread as in
//! the headset, the controllers untracked), for the length of its script, on each scheme:
//! simulation frames a second and the tool-to-tissue latency — a shown frame's display time
//! minus that of the frame whose tool command the tissue it shows was stepped with — as
//! `incise xr` reports them (`xr_report.json`). The eyes are drawn small (64 × 64), yet a
//! software renderer (lavapipe) still draws every skin triangle on the cores the solver
//! runs on (the default organ's 46,592: about 28 ms of the cores a frame), which a
//! headset's GPU takes off them; so each scheme also runs with the eyes prepared but not
//! drawn (`draw_eyes: false`): the latency the simulation alone adds.

use std::path::Path;

use anyhow::{Context, Result};
use incise_sim::implicit::Scheme;

use super::XrOptions;
use super::sim_mode::SimChoice;
use crate::sim_body::DeviceChoice;

/// Display rate of the simulated headset, Hz (Quest 3's).
const DISPLAY_HZ: f64 = 72.0;

/// What one simulated session measured.
#[derive(Debug, Clone, Copy)]
pub struct HeadsetRun {
    /// Simulation frames a second of wall time.
    pub sim_fps: f64,
    /// Tool-to-tissue latency, median and 95th percentile, ms.
    pub latency_ms: (f64, f64),
    /// The share (0..1) of the frames within one display period + 15 ms of their pose.
    pub within: f64,
}

/// The headset script: Quest 3's rate on the wall clock for `seconds`, every frame drawn
/// at 64 × 64 an eye (or, not `draw`, prepared but not drawn), the head above the tray
/// looking down.
fn script(seconds: f64, draw: bool) -> String {
    format!(
        "(display_hz: {DISPLAY_HZ}, duration: {seconds}, eye_size: (64, 64), render_every: 1, \
         draw_eyes: {draw}, realtime: true,\n head: [(t: 0.0, position: (0.0, 1.25, -0.05), \
         orientation: (-0.34202, 0.0, 0.0, 0.93969))])"
    )
}

/// Run `scene` on `scheme` (its own: `None`) in the simulated headset for `seconds`, the
/// eyes drawn or not (`draw`); `dir` holds the script and the session's outputs.
pub fn run(
    scene: &Path,
    scheme: Option<Scheme>,
    (seconds, draw): (f64, bool),
    dir: &Path,
) -> Result<HeadsetRun> {
    std::fs::create_dir_all(dir)?;
    let script_path = dir.join("headset.ron");
    std::fs::write(&script_path, script(seconds, draw))?;
    let out = dir.join("session");
    let opts = XrOptions {
        scene: scene.to_path_buf(),
        simulated: Some(script_path),
        out: out.clone(),
        record_stroke: None,
        frames: None,
        device: DeviceChoice::Cpu,
        exercise: None,
        history: dir.join("history.jsonl"),
        inject_nan_at: None,
        stroke: None,
        sim: SimChoice::Thread,
        slow_sim_ms: 0,
        inject_sim_panic_at: None,
        scheme,
    };
    crate::xr::run(&opts).context("the simulated headset")?;
    let text = std::fs::read_to_string(out.join("xr_report.json"))?;
    let report: serde_json::Value = serde_json::from_str(&text)?;
    let latency = &report["tool_latency_ms_p50_p95"];
    let (p50, p95) = latency[0]
        .as_f64()
        .zip(latency[1].as_f64())
        .context("the simulated headset showed no frame with a tool command")?;
    let sim_fps = report["sim_steps_per_s"]
        .as_f64()
        .context("the simulated headset's report has no simulation rate")?;
    let within = report["tool_latency_within_period_15ms"]
        .as_f64()
        .context("the simulated headset's report has no latency share")?;
    Ok(HeadsetRun {
        sim_fps,
        latency_ms: (p50, p95),
        within,
    })
}

/// The schemes the headset table compares on a scene whose scheme is `own`: its own
/// first, then the other one (XPBD at its substeps, or the implicit scheme with the
/// defaults).
fn schemes(own: Scheme) -> [Scheme; 2] {
    match own {
        Scheme::Xpbd => [own, Scheme::Newton(own.newton_or_default())],
        Scheme::Newton(_) => [own, Scheme::Xpbd],
    }
}

/// `scene` on both schemes in the simulated headset, `runs` interleaved runs each, as the
/// markdown table under docs/performance.md's realtime table (min–max over the runs).
pub fn markdown(scene: &Path, runs: usize) -> Result<String> {
    let loaded = crate::scene::load_scene(scene)?;
    let seconds = loaded.duration as f64;
    let substeps = loaded.solver.substeps;
    let schemes = schemes(loaded.solver.scheme);
    let dir = std::env::temp_dir().join(format!("incise-bench-headset-{}", std::process::id()));
    let cases: Vec<(Scheme, bool)> = schemes
        .iter()
        .flat_map(|s| [(*s, true), (*s, false)])
        .collect();
    let mut got: Vec<Vec<HeadsetRun>> = vec![Vec::new(); cases.len()];
    for r in 0..runs {
        for (k, (scheme, draw)) in cases.iter().enumerate() {
            let at = dir.join(format!("{k}-{r}"));
            got[k].push(run(scene, Some(*scheme), (seconds, *draw), &at)?);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    let span = |v: Vec<f64>, digits: usize| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        format!("{lo:.digits$}–{hi:.digits$}")
    };
    // The script leaves the controllers untracked: a scalpel scene's blade stays out.
    let blade = match loaded.tool {
        Some(_) => {
            " The controllers are untracked, so the scene's scalpel never reaches the \
             tissue: these are its frames without the incision (the table above times the \
             whole scene with it)."
        }
        None => "",
    };
    let mut s = format!(
        "\nHeadset: a simulated Quest 3 on the wall clock at {DISPLAY_HZ} Hz for the scene's \
         {seconds:.1} s, the simulation on its own thread, the eyes 64 × 64 \
         (`incise xr SCENE --simulated-headset`), {runs} interleaved runs each (min–max).{blade} \
         Drawn: by the software renderer, on the cores the solver runs on. Not drawn \
         (`draw_eyes: false`): each frame's picture taken and uploaded, its drawing left to \
         a GPU that is not there, as a headset's GPU takes it off the cores. Within: the \
         share of the frames shown at most one display period + 15 ms after their pose \
         (issue 31's bound on the median, met where the share is at least 50 %):\n\n\
         | scheme | eyes | simulation frames / s | tool-to-tissue latency p50, ms | p95, ms | within, % |\n\
         |---|---|---|---|---|---|\n"
    );
    for ((scheme, draw), rs) in cases.iter().zip(got) {
        let name = match scheme {
            Scheme::Xpbd => format!("XPBD, {substeps} substeps"),
            Scheme::Newton(_) => scheme.name().to_string(),
        };
        let eyes = if *draw { "drawn" } else { "not drawn" };
        s += &format!(
            "| {name} | {eyes} | {} | {} | {} | {} |\n",
            span(rs.iter().map(|r| r.sim_fps).collect(), 1),
            span(rs.iter().map(|r| r.latency_ms.0).collect(), 0),
            span(rs.iter().map(|r| r.latency_ms.1).collect(), 0),
            span(rs.iter().map(|r| 100.0 * r.within).collect(), 0),
        );
    }
    Ok(s)
}

/// Print [`markdown`] for `scene` with [`crate::bench::realtime::MARKDOWN_RUNS`] runs; the
/// simulated eyes need a renderer, and without one a line says why (the benchmark's table
/// above it stands).
pub fn print(scene: &Path) {
    match markdown(scene, crate::bench::realtime::MARKDOWN_RUNS) {
        Ok(table) => print!("{table}"),
        Err(e) => println!("\nHeadset: not measured: {e:#}"),
    }
}
