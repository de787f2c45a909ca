//! `incise exercise`: run the exercise's scene with a stroke driving its scalpel (the
//! `incise run` machinery, unchanged), measure the cut, score it, write `result.json`
//! and `report.html`, and append the attempt to the results history. Scoring a
//! simulation state ([`score_attempt`]) and saving an attempt ([`save_attempt`]) are
//! the same for the preview's and the headset's live attempts.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use super::history::{self, HistoryEntry};
use super::load::{LoadedExercise, load_exercise};
use super::metrics::{self, ToolFrame};
use super::report_html::{self, CutImages};
pub use super::result::ExerciseResult;
use super::score;
use crate::pictures::screenshots::ImageSize;
use crate::run::{RunOptions, run_scene};
use crate::scene::ModelChoice;
use crate::sim_body::{DeviceChoice, RestCut};

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

/// Score `opts.stroke` on `opts.exercise`: the stroke replayed by `incise run`'s
/// machinery for its duration plus `SETTLE_TIME` (0.2 s), then [`score_attempt`] and
/// [`save_attempt`] into `opts.out`.
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
        replay_localisation: None,
        inject_gpu_loss_at: None,
        inject_nan_at: None,
        // The plan is drawn on XPBD bodies (a Nakao cut remodels the tets it is laid in).
        screenshot_decal: matches!(ex.scene.model, ModelChoice::Xpbd)
            .then(|| ex.plan.decal(&ex.mesh)),
    })
    .with_context(|| format!("{}: running the attempt", opts.exercise.display()))?;
    let report = outcome.report;
    let cut = outcome.rest_cut.with_context(|| {
        format!(
            "{}: a {} body leaves no cut to score",
            ex.scene_path.display(),
            report.method.name()
        )
    })?;
    let tool: Vec<ToolFrame> = report
        .frames
        .iter()
        .map(|f| ToolFrame::of(&f.stats))
        .collect();
    let result = score_attempt(
        &ex,
        &opts.stroke.display().to_string(),
        report.device.clone(),
        &cut,
        &tool,
        frames,
    )?;
    let first = opts.out.join("frame_00000.png");
    let last = opts.out.join(format!("frame_{frames:05}.png"));
    let pictures = match images {
        None => CutImages::Files(vec![
            ("Before the attempt", first.as_path()),
            ("After the attempt", last.as_path()),
        ]),
        Some(why) => CutImages::Missing(why),
    };
    save_attempt(&opts.out, result, &pictures, &opts.history)
}

/// Score an attempt on `ex` from what its body cut (`cut`, at rest: released tets of the
/// exercise's mesh or a cut surface), the tool figures of each of the `frames` simulated
/// frames (`tool`), the stroke (`stroke_label`, as written in the results) and the
/// solver's `device`. The one scoring of the command line, the preview and the headset.
pub fn score_attempt(
    ex: &LoadedExercise,
    stroke_label: &str,
    device: String,
    cut: &RestCut,
    tool: &[ToolFrame],
    frames: u64,
) -> Result<ExerciseResult> {
    if let RestCut::Released(released) = cut
        && released.len() != ex.mesh.tet_count()
    {
        bail!(
            "{}: the attempt's body has {} tets, the exercise's mesh {}: not the exercise's \
             scene",
            ex.path.display(),
            released.len(),
            ex.mesh.tet_count()
        );
    }
    let dt = ex.scene.solver.frame_dt as f64;
    let metrics = metrics::compute(&ex.exercise, &ex.plan, &ex.mesh, cut, tool, dt);
    let verdict = score::judge(&ex.exercise, &metrics);
    let e = &ex.exercise;
    Ok(ExerciseResult {
        exercise: e.name.clone(),
        method: ex.scene.model.method(),
        exercise_file: ex.path.display().to_string(),
        description: e.description.clone(),
        scene_file: ex.scene_path.display().to_string(),
        stroke_file: stroke_label.to_string(),
        device,
        time: history::utc_now(),
        frames,
        plan: ex.plan.points.iter().map(|p| p.to_array()).collect(),
        target_depth: e.depth,
        tolerance: e.tolerance,
        time_limit: e.time_limit,
        thresholds: e.pass,
        metrics,
        verdict,
    })
}

/// Save a scored attempt into `out_dir` (created): `result.json` (atomically),
/// `report.html` with `images` and its plots, and one line appended to the results
/// history at `history_path`.
pub fn save_attempt(
    out_dir: &Path,
    result: ExerciseResult,
    images: &CutImages,
    history_path: &Path,
) -> Result<Attempt> {
    std::fs::create_dir_all(out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    let result_path = out_dir.join("result.json");
    incise_sim::io::write_atomic(
        &result_path,
        serde_json::to_string_pretty(&result)?.as_bytes(),
    )
    .with_context(|| format!("writing {}", result_path.display()))?;
    let html_path = report_html::write(out_dir, &result, images)?;
    history::append(
        history_path,
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
