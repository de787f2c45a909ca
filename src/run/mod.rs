//! `incise run`: the headless runner. Opens a scene's body (any method), steps it in the
//! one frame loop, writes report.json, .vtu snapshots and a .pvd collection; on a solver
//! failure the output written so far is kept and the report says what failed.

pub mod ending;
pub mod frame_loop;
pub mod options;

pub use ending::{RunEnd, finish};
pub use options::{CHECKPOINT_FRAMES, RunOptions, RunOutcome};

use anyhow::{Context, Result, anyhow, bail};

use crate::scene::{ModelChoice, load_scene};
use crate::sim_body::{OpenOptions, open};
use frame_loop::FrameLoop;

/// Run a scene headless: open its body, run the frames, let the body fill in its
/// end-of-run figures, and end as every run does. A solver failure is returned as `Err`
/// after the report and the snapshots so far have been written.
pub fn run_scene(opts: &RunOptions) -> Result<RunOutcome> {
    let scene = load_scene(&opts.scene)?;
    refuse_xpbd_only_options(&scene.model, opts)?;
    if opts.replay_localisation.is_some()
        && (!matches!(scene.model, ModelChoice::MassSpring(_)) || opts.haptic_rate.is_some())
    {
        bail!(
            "{}: --replay-localisation replays a mass-spring scene's frame-by-frame \
             localisation (not with --haptic-rate)",
            opts.scene.display()
        );
    }
    let (body, report) = open(&scene, &opts.scene, &open_options(opts)?)?;
    let frames = opts
        .frames
        .unwrap_or_else(|| scene.frame_count(body.frame_dt()));
    let (mut body, mut report, stopped) =
        FrameLoop::new(body, report, opts, frames)?.run(frames)?;
    let closing = body.finish(&mut report)?;
    if let Some(line) = closing.filter(|_| !opts.quiet && stopped.is_none()) {
        eprintln!("{line}");
    }
    let rest_cut = body.rest_cut();
    finish(
        report,
        opts.out.join("report.json"),
        stopped,
        opts,
        rest_cut,
    )
}

/// What of `opts` the body is opened with (a replayed localisation read from its report).
fn open_options(opts: &RunOptions) -> Result<OpenOptions> {
    let free_nodes = match &opts.replay_localisation {
        Some(path) => Some(replayed_free_nodes(path)?),
        None => None,
    };
    Ok(OpenOptions {
        threads: opts.threads,
        device: opts.device,
        stroke: opts.stroke.clone(),
        haptic_rate: opts.haptic_rate,
        quiet: opts.quiet,
        hand: false,
        script_until_taken: false,
        gpu: None,
        free_nodes,
        scheme: None,
    })
}

/// The free nodes of every localised frame (one with a `level`) of the report at `path`.
fn replayed_free_nodes(path: &std::path::Path) -> Result<Vec<usize>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--replay-localisation: reading {}", path.display()))?;
    let report: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("--replay-localisation: {} is not JSON", path.display()))?;
    let frames = report["frames"]
        .as_array()
        .ok_or_else(|| anyhow!("--replay-localisation: {} has no frames", path.display()))?;
    frames
        .iter()
        .filter(|f| !f["level"].is_null())
        .map(|f| {
            f["free_nodes"].as_u64().map(|n| n as usize).ok_or_else(|| {
                anyhow!(
                    "--replay-localisation: {}: frame {} has a level but no free_nodes",
                    path.display(),
                    f["frame"]
                )
            })
        })
        .collect()
}

/// A stroke file drives the XPBD scalpel or the Nakao blade; recording a stroke is the
/// XPBD scalpel's (the Nakao blade shows no turn). Refused for the methods without them.
fn refuse_xpbd_only_options(model: &ModelChoice, opts: &RunOptions) -> Result<()> {
    let Some(method) = model.non_xpbd_name() else {
        return Ok(());
    };
    let nakao = matches!(model, ModelChoice::MassSpring(_));
    for (given, flag, drives) in [
        (
            opts.stroke.is_some() && !nakao,
            "--stroke",
            "the XPBD scalpel and the Nakao blade",
        ),
        (
            opts.record_stroke.is_some(),
            "--record-stroke",
            "the XPBD scalpel's poses",
        ),
    ] {
        if given {
            bail!(
                "{}: {flag} is for {drives}; this scene's model is {method}, whose tool \
                 follows model.stroke or model.indenter",
                opts.scene.display()
            );
        }
    }
    Ok(())
}
