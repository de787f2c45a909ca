//! `incise exercise`: run the exercise's scene with a stroke driving its scalpel (the
//! `incise run` machinery, unchanged), measure the cut, score it, write `result.json`
//! and `report.html`, and append the attempt to the results history.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use serde::Serialize;

use super::history::{self, HistoryEntry};
use super::load::load_exercise;
use super::metrics::{self, Metrics};
use super::model::{PassThresholds, Tolerance};
use super::report_html::{self, CutImages};
use super::score::{self, Verdict};
use crate::body::DeviceChoice;
use crate::report::FrameData;
use crate::run::{RunOptions, run_scene};
use crate::screenshots::ImageSize;

/// Simulated time after the stroke's last key, so the tissue settles and late releases
/// are counted, s.
const SETTLE_TIME: f64 = 0.2;

/// Options of `incise exercise`.
#[derive(Debug, Clone)]
pub struct ExerciseOptions {
    /// Exercise file.
    pub exercise: PathBuf,
    /// Stroke file driving the scalpel.
    pub stroke: PathBuf,
    /// Output folder (result.json, report.html, report.json, plots, pictures).
    pub out: PathBuf,
    /// Where the solver runs.
    pub device: DeviceChoice,
    /// History file the attempt is appended to.
    pub history: PathBuf,
    /// No progress output.
    pub quiet: bool,
}

/// Everything `result.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct ExerciseResult {
    /// Exercise name.
    pub exercise: String,
    /// Exercise file.
    pub exercise_file: String,
    /// The exercise's description.
    pub description: String,
    /// Scene file.
    pub scene_file: String,
    /// Stroke file.
    pub stroke_file: String,
    /// Device the solver ran on.
    pub device: String,
    /// When it was scored, UTC.
    pub time: String,
    /// Frames simulated.
    pub frames: u64,
    /// The plan projected onto the organ's rest surface, m.
    pub plan: Vec<[f64; 3]>,
    /// Target depth, m.
    pub target_depth: f32,
    /// Tolerance band.
    pub tolerance: Tolerance,
    /// Time limit, s.
    pub time_limit: f32,
    /// Pass thresholds.
    pub thresholds: PassThresholds,
    /// The measurements.
    pub metrics: Metrics,
    /// Score and checks.
    pub verdict: Verdict,
}

/// What a scored attempt produced.
#[derive(Debug)]
pub struct Attempt {
    /// The result.
    pub result: ExerciseResult,
    /// Path of result.json.
    pub result_path: PathBuf,
    /// Path of report.html.
    pub html_path: PathBuf,
}

/// Score `opts.stroke` on `opts.exercise`.
pub fn run_exercise(opts: &ExerciseOptions) -> Result<Attempt> {
    let ex = load_exercise(&opts.exercise)?;
    let stroke = incise_scalpel::load_stroke(&opts.stroke)?;
    let dt = ex.scene.solver.frame_dt as f64;
    let frames = ((stroke.end_time() + SETTLE_TIME) / dt).ceil().max(1.0) as u64;
    let images = match incise_xr::RenderDevice::headless() {
        Ok(_) => None,
        Err(e) => Some(format!("no offscreen renderer ({e})")),
    };
    let outcome = run_scene(&RunOptions {
        scene: ex.scene_path.clone(),
        frames: Some(frames),
        out: opts.out.clone(),
        vtu_every: 0,
        threads: None,
        quiet: opts.quiet,
        device: opts.device,
        screenshot_every: if images.is_none() { frames } else { 0 },
        screenshot_size: ImageSize(960, 540),
        haptic_rate: None,
        stroke: Some(opts.stroke.clone()),
        record_stroke: None,
        inject_gpu_loss_at: None,
        inject_nan_at: None,
    })
    .with_context(|| format!("{}: running the attempt", opts.exercise.display()))?;
    let report = outcome.report;
    let mut released = vec![false; ex.mesh.tet_count()];
    for &t in &report.released_tets {
        released[t as usize] = true;
    }
    let stats: Vec<_> = report
        .frames
        .iter()
        .filter_map(|f| match &f.stats {
            FrameData::Xpbd(s) => Some(s.clone()),
            FrameData::Edges(_) => None,
        })
        .collect();
    if stats.len() != report.frames.len() {
        bail!("{}: exercises need an Xpbd scene", ex.scene_path.display());
    }
    let metrics = metrics::compute(&ex.exercise, &ex.plan, &ex.mesh, &released, &stats, dt);
    let verdict = score::judge(&ex.exercise, &metrics);
    let e = &ex.exercise;
    let result = ExerciseResult {
        exercise: e.name.clone(),
        exercise_file: opts.exercise.display().to_string(),
        description: e.description.clone(),
        scene_file: ex.scene_path.display().to_string(),
        stroke_file: opts.stroke.display().to_string(),
        device: report.device.clone(),
        time: history::utc_now(),
        frames,
        plan: ex.plan.points.iter().map(|p| p.to_array()).collect(),
        target_depth: e.depth,
        tolerance: e.tolerance,
        time_limit: e.time_limit,
        thresholds: e.pass,
        metrics,
        verdict,
    };
    let result_path = opts.out.join("result.json");
    std::fs::write(&result_path, serde_json::to_string_pretty(&result)?)
        .with_context(|| format!("writing {}", result_path.display()))?;
    let first = opts.out.join("frame_00000.png");
    let last = opts.out.join(format!("frame_{frames:05}.png"));
    let pictures = match images {
        None => CutImages::Files(vec![
            ("Before the attempt", first.as_path()),
            ("After the attempt", last.as_path()),
        ]),
        Some(why) => CutImages::Missing(why),
    };
    let html_path = report_html::write(&opts.out, &result, &pictures)?;
    history::append(
        &opts.history,
        &HistoryEntry {
            time: result.time.clone(),
            exercise: result.exercise.clone(),
            stroke: result.stroke_file.clone(),
            score: result.verdict.score,
            passed: result.verdict.passed,
            completion: result.metrics.completion,
            mean_deviation: result.metrics.mean_deviation,
            mean_depth_error: result.metrics.mean_depth_error,
            collateral_volume: result.metrics.collateral_volume,
            max_force: result.metrics.max_force,
            strokes: result.metrics.strokes,
            duration: result.metrics.duration,
            result: result_path.display().to_string(),
        },
    )?;
    Ok(Attempt {
        result,
        result_path,
        html_path,
    })
}

impl ExerciseResult {
    /// A few lines for the terminal: verdict, score and every failed condition.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "{}: {} — score {:.0} / 100",
            self.exercise,
            if self.verdict.passed { "PASS" } else { "FAIL" },
            self.verdict.score
        );
        for c in self.verdict.checks.iter().filter(|c| !c.passed) {
            s.push_str(&format!("\n  failed {}: {}", c.name, c.detail));
        }
        s
    }
}
