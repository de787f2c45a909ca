//! `incise bench scene`: the frames of any scene's body (any method) stepped through
//! [`SimBody`](crate::sim_body::SimBody) by its own script, as `incise run` steps them:
//! method, nodes and tets, ms per frame (min, median, p99); for a Nakao body the
//! localisation levels it chose and its per-loop split (from the report's localisation
//! section).

use std::path::Path;
use std::time::Instant;

use anyhow::{Result, anyhow, bail};
use serde::Serialize;

use crate::bench::BenchOutput;
use crate::quantile::percentile;
use crate::report::localisation::LocalisationInfo;
use crate::scene::Method;
use crate::scene::load_scene;
use crate::sim_body::{DeviceChoice, OpenOptions, ToolInput, open};

/// The figures of one scene's frames.
#[derive(Debug, Clone, Serialize)]
pub struct SceneBench {
    /// Scene file.
    pub scene: String,
    /// The scene's method.
    pub method: Method,
    /// Where the body ran.
    pub device: String,
    /// Nodes when opened.
    pub nodes: usize,
    /// Tets when opened.
    pub tets: usize,
    /// Frames timed (from the start of the scene's script).
    pub frames: usize,
    /// Fastest frame, wall ms.
    pub frame_ms_min: f64,
    /// Median frame, wall ms.
    pub frame_ms_median: f64,
    /// 99th-percentile frame, wall ms.
    pub frame_ms_p99: f64,
    /// The Nakao body's levels, free nodes and loop split over the frames.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub localisation: Option<LocalisationInfo>,
}

/// Time the first `frames` frames of `scene` on `device` and print them as `output` asks.
pub fn run(scene: &Path, device: DeviceChoice, frames: u32, output: BenchOutput) -> Result<()> {
    let r = measure(scene, device, frames)?;
    match output {
        BenchOutput::Json => println!("{}", serde_json::to_string_pretty(&r)?),
        BenchOutput::Table => println!("{}", summary(&r)),
        BenchOutput::Markdown => bail!("bench scene prints text or --json; no markdown table"),
    }
    Ok(())
}

/// Step `frames` frames of `scene_path`'s script, timing each.
pub fn measure(scene_path: &Path, device: DeviceChoice, frames: u32) -> Result<SceneBench> {
    let scene = load_scene(scene_path)?;
    let opts = OpenOptions {
        device,
        ..OpenOptions::default()
    };
    let (mut body, mut report) = open(&scene, scene_path, &opts)?;
    let (nodes, tets) = (report.mesh.nodes, report.mesh.tets);
    let mut times = Vec::with_capacity(frames as usize);
    for f in 0..frames.max(1) {
        let t0 = Instant::now();
        body.step(&ToolInput::Script)
            .map_err(|e| anyhow!("{}: frame {f}: {e}", scene_path.display()))?;
        times.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    body.finish(&mut report)?;
    times.sort_by(f64::total_cmp);
    Ok(SceneBench {
        scene: scene_path.display().to_string(),
        method: body.method(),
        device: body.device(),
        nodes,
        tets,
        frames: times.len(),
        frame_ms_min: times[0],
        frame_ms_median: percentile(&times, 0.5),
        frame_ms_p99: percentile(&times, 0.99),
        localisation: report.localisation,
    })
}

/// The figures as text: a line, and for a Nakao body a line of its localisation.
fn summary(r: &SceneBench) -> String {
    let mut s = format!(
        "{} ({} on {}): {} nodes, {} tets; {} frames: {:.2} ms/frame min, {:.2} median, {:.2} p99",
        r.scene,
        r.method.name(),
        r.device,
        r.nodes,
        r.tets,
        r.frames,
        r.frame_ms_min,
        r.frame_ms_median,
        r.frame_ms_p99
    );
    if let Some(l) = &r.localisation {
        let levels = l.level.as_ref().map_or("whole mesh".to_string(), |v| {
            format!("levels {:.0}–{:.0}", v.min, v.max)
        });
        s += &format!(
            "\nlocalisation {}: {levels}, free nodes {:.0}–{:.0}; loop split (mean ms) localise {:.3}, force {:.3}, integrate {:.3}, cut {:.3}",
            l.mode,
            l.free_nodes.min,
            l.free_nodes.max,
            l.localise_ms.mean,
            l.force_ms.mean,
            l.integrate_ms.mean,
            l.cut_ms.mean
        );
    }
    s
}
