//! `incise xr [SCENE]`: the scene on a tray in the room, cut with the right controller
//! (issue 7). With `--simulated-headset SCRIPT.ron` the same frame loop runs without a
//! runtime on a scripted headset, rendering both eyes offscreen.

pub mod exercise;
pub mod frame_log;
pub mod frame_loop;
pub mod in_frame;
pub mod latest;
pub mod method_session;
pub mod method_thread;
pub mod script;
pub mod sim_mode;
pub mod sim_source;
pub mod sim_state;
pub mod sim_step;
pub mod sim_thread;
pub mod simulated;
pub mod unavailable;
pub mod xr_body;

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};
use incise_scalpel::HapticCurve;
use incise_xr::RenderDevice;
use incise_xr::openxr::scalpel_pose::BladeOffset;
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{Headset, XrSession};
use serde::Serialize;

use crate::sim_body::DeviceChoice;
use exercise::{AttemptSummary, XrExercise};
use frame_loop::{LoopOptions, LoopOutcome, run_loop};
use script::{HeadsetScript, Pacing, RightTrack};
use sim_mode::{SimChoice, SimMode};
use sim_step::SimFaults;
use simulated::SimulatedHeadset;
pub use unavailable::XrUnavailable;
use xr_body::XrBody;

/// What `incise xr` was asked.
#[derive(Debug, Clone)]
pub struct XrOptions {
    /// Scene file.
    pub scene: PathBuf,
    /// Run on a simulated headset playing this script instead of a runtime.
    pub simulated: Option<PathBuf>,
    /// Output folder: frame log, report, eye images, recorded stroke.
    pub out: PathBuf,
    /// Also write the scalpel's recorded stroke here (it is always written to the
    /// output folder as `stroke.ron`).
    pub record_stroke: Option<PathBuf>,
    /// Stop after this many display frames.
    pub frames: Option<u64>,
    /// Where the solver runs.
    pub device: DeviceChoice,
    /// Run this training exercise (its scene instead of `scene`): the plan drawn on the
    /// tissue, attempts scored and saved under `out/attempts/`.
    pub exercise: Option<PathBuf>,
    /// Results history exercise attempts are appended to.
    pub history: PathBuf,
    /// Testing aid: a NaN in the solver just before this simulation frame.
    pub inject_nan_at: Option<u64>,
    /// Drive the scalpel along this recorded stroke (simulation time) instead of the
    /// right controller; the session ends when it has been played.
    pub stroke: Option<PathBuf>,
    /// Where the solver is stepped (its own thread by default).
    pub sim: SimChoice,
    /// Testing aid: sleep this long in every simulation frame (an artificially slow
    /// solver).
    pub slow_sim_ms: u64,
    /// Testing aid: a panic in the simulation just before this simulation frame.
    pub inject_sim_panic_at: Option<u64>,
}

/// The session summary written as `xr_report.json`.
#[derive(Debug, Serialize)]
pub struct XrReport {
    /// Scene file.
    pub scene: String,
    /// The headset (runtime name or "simulated …") and render device.
    pub headset: String,
    /// Solver device.
    pub solver_device: String,
    /// Where the solver was stepped: "thread" (its own thread, paced to real time; each
    /// display frame renders its latest completed state) or "in-frame" (inside each
    /// display frame, which waits for it).
    pub sim_mode: String,
    /// Why that mode.
    pub sim_mode_why: String,
    /// Display frames (begun by the runtime's frame loop).
    pub frames: u64,
    /// Display frames rendered (ended with a projection layer).
    pub rendered: u64,
    /// Simulation frames stepped.
    pub sim_frames: u64,
    /// The session states the runtime reported, in order (IDLE first).
    pub session_states: Vec<String>,
    /// Released tets at the end.
    pub released_tets: usize,
    /// Where the cut is: the bounding box (min, max, sim world, m) of the released tets'
    /// rest centroids.
    pub cut_box: Option<xr_body::CutBox>,
    /// Largest tool force, N.
    pub max_tool_force: f32,
    /// Largest vibration amplitude.
    pub max_haptic: f32,
    /// Vibration pulses sent.
    pub haptic_pulses: u64,
    /// Vibration stops sent (once each time the blade left the tissue).
    pub haptic_stops: u64,
    /// Simulated time given up, s.
    pub dropped_time_s: f64,
    /// The display rate the runtime reported, Hz.
    pub display_hz: f64,
    /// Display frames the runtime skipped because a frame came late.
    pub dropped_frames: u64,
    /// Simulation frames stepped per second of wall time (over the simulation's wall
    /// time: the thread's, from its first command; in the frame, the session's).
    pub sim_steps_per_s: f64,
    /// Tool-to-tissue latency, median and 95th percentile over rendered frames, ms: a
    /// frame's predicted display time minus that of the frame whose tool pose (sampled
    /// for its predicted display time) was the newest the tissue it shows was stepped
    /// with (`frames.csv`: tool_latency_ms).
    pub tool_latency_ms_p50_p95: Option<(f64, f64)>,
    /// The testing aid's sleep per simulation frame, ms (0: none).
    pub slow_sim_ms: u64,
    /// Scene substeps and the fewest used.
    pub substeps: (u32, u32),
    /// Median and 95th-percentile wall time of rendered frames, ms.
    pub frame_ms_p50_p95: Option<(f64, f64)>,
    /// Times the solver failed (an inverted tet) and the scene was reset.
    pub solver_resets: u32,
    /// How the session ended.
    pub exit: String,
    /// The recorded stroke, if any.
    pub stroke: Option<String>,
    /// The stroke file that drove the scalpel (`--stroke`), if any.
    pub played_stroke: Option<String>,
    /// The exercise file, in an exercise session.
    pub exercise: Option<String>,
    /// The exercise attempts finished and saved in the session.
    pub attempts: Vec<AttemptSummary>,
}

/// Run `incise xr`; the session's summary line. A scene of another method than XPBD runs
/// a [`method_session`] (no exercise). No usable runtime: an [`XrUnavailable`] error
/// (exit 2).
pub fn run(opts: &XrOptions) -> Result<String> {
    if opts.exercise.is_none() {
        let scene = crate::scene::load_scene(&opts.scene)?;
        if !matches!(scene.model, crate::scene::ModelChoice::Xpbd) {
            return run_method(opts);
        }
    }
    run_xpbd(opts).map(|r| r.summary())
}

/// `incise xr` for a Nakao or rheology scene, on the simulated headset or the runtime's.
fn run_method(opts: &XrOptions) -> Result<String> {
    let sim = method_session::MethodSim {
        choice: opts.sim,
        slow: Duration::from_millis(opts.slow_sim_ms),
        frames: opts.frames,
    };
    if let Some(script) = &opts.simulated {
        return method_session::run_simulated(&opts.scene, script, &opts.out, &sim);
    }
    let mut session = open_session(&opts.scene)?;
    method_session::run_on_runtime(&mut session, &opts.scene, &opts.out, &sim)
}

/// The OpenXR session, or [`XrUnavailable`] naming what is missing.
fn open_session(scene: &Path) -> Result<XrSession> {
    XrSession::open().map_err(|e| {
        if e.is_unavailable() {
            anyhow::Error::new(XrUnavailable(unavailable::message(&e, scene)))
        } else {
            anyhow::Error::new(e).context("starting the OpenXR session")
        }
    })
}

/// `incise xr` for an XPBD scene (and exercises).
fn run_xpbd(opts: &XrOptions) -> Result<XrReport> {
    let mut exercise = opts
        .exercise
        .as_ref()
        .map(|p| XrExercise::open(p, &opts.out.join("attempts"), &opts.history))
        .transpose()?;
    let scene = match &exercise {
        Some(e) => e.exercise().scene_path.clone(),
        None => opts.scene.clone(),
    };
    match &opts.simulated {
        Some(script) => run_simulated(opts, &scene, script, exercise.as_mut()),
        None => {
            let mut session = open_session(&scene)?;
            eprintln!("xr: backdrop {:?}", session.backdrop());
            let dev = session.device().clone();
            let mode = sim_mode::resolve(opts.sim, exercise.is_some(), false)?;
            let solver_dev = solver_device(opts.device, mode.0, &dev)?;
            let (mut xr, skin) = XrBody::load(&scene, opts.device, &solver_dev)?;
            let tray = tray_for(&xr);
            run_session(
                &mut session,
                &mut xr,
                &skin,
                opts,
                (tray, false, mode),
                exercise.as_mut(),
            )
        }
    }
}

/// The device a GPU solver runs on: on the simulation thread its own (a second logical
/// device with its own queue, on the best adapter: [`RenderDevice::separate`]), so its
/// submissions and waits never hold up the renderer's on the headset's device (measured
/// on lavapipe, sharing it made the display wait: 66 of 120 refreshes dropped on
/// Monado); in the frame, or for a CPU solver, the renderer's.
fn solver_device(choice: DeviceChoice, mode: SimMode, dev: &RenderDevice) -> Result<RenderDevice> {
    match (choice, mode) {
        (DeviceChoice::Cpu, _) | (_, SimMode::InFrame) => Ok(dev.clone()),
        _ => RenderDevice::separate().context("opening the simulation thread's GPU device"),
    }
}

fn tray_for(xr: &XrBody) -> Tray {
    let (lo, hi) = xr.solver().mesh().rest_bounds();
    Tray::for_bounds(lo, hi)
}

fn run_simulated(
    opts: &XrOptions,
    scene: &Path,
    script_path: &Path,
    exercise: Option<&mut XrExercise>,
) -> Result<XrReport> {
    let script = HeadsetScript::load(script_path)?;
    let dev = RenderDevice::headless()?;
    let device = match opts.device {
        DeviceChoice::Auto => DeviceChoice::Cpu,
        d => d,
    };
    let mode = sim_mode::resolve(opts.sim, exercise.is_some(), !script.realtime)?;
    let (mut xr, skin) = XrBody::load(scene, device, &solver_device(device, mode.0, &dev)?)?;
    let tray = tray_for(&xr);
    let stroke = match &script.right {
        Some(RightTrack::Tool { stroke, .. }) => Some(match stroke {
            crate::scene::ToolStroke::File(f) => incise_scalpel::load_stroke(
                &script_path.parent().unwrap_or(Path::new(".")).join(f),
            )?,
            crate::scene::ToolStroke::Incision(i) => crate::scene::incision(xr.scalpel(), i)
                .with_context(|| format!("{}: right.stroke", script_path.display()))?,
        }),
        _ => None,
    };
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let nominal = script.pacing == Pacing::Nominal;
    let mut headset =
        SimulatedHeadset::new(script, stroke, tray, BladeOffset::default(), dev, &opts.out)?;
    run_session(
        &mut headset,
        &mut xr,
        &skin,
        opts,
        (tray, nominal, mode),
        exercise,
    )
}

/// The tray at the start, whether the headset asks for the scene's substeps always, and
/// the simulation mode with why.
type SessionSetup = (Tray, bool, (SimMode, String));

fn run_session(
    headset: &mut dyn Headset,
    xr: &mut XrBody,
    skin: &incise_sim::skin::Skin,
    opts: &XrOptions,
    (tray, nominal_pacing, (sim_mode, sim_mode_why)): SessionSetup,
    mut exercise: Option<&mut XrExercise>,
) -> Result<XrReport> {
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let curve = HapticCurve::default();
    let haptic = move |f: f32| curve.amplitude(f);
    let played = opts
        .stroke
        .as_ref()
        .map(|p| {
            incise_scalpel::load_stroke(p).with_context(|| format!("--stroke {}", p.display()))
        })
        .transpose()?;
    let describe = headset.describe();
    eprintln!("xr: {describe}");
    eprintln!("xr: simulation {} ({sim_mode_why})", sim_mode.name());
    let mut outcome: LoopOutcome = run_loop(
        headset,
        xr,
        skin,
        &LoopOptions {
            max_frames: opts.frames,
            blade: BladeOffset::default(),
            haptic: &haptic,
            // A played stroke keeps the scene's substeps, so its recording replays with
            // `incise run --stroke` through the same physics.
            nominal_pacing: nominal_pacing || played.is_some(),
            record: true,
            tray,
            stroke: played.as_ref(),
            sim_mode,
            faults: SimFaults {
                nan_at: opts.inject_nan_at,
                panic_at: opts.inject_sim_panic_at,
                slow: Duration::from_millis(opts.slow_sim_ms),
            },
        },
        exercise.as_deref_mut(),
    )?;
    outcome.log.save(&opts.out.join("frames.csv"))?;
    let mut stroke_path = None;
    if let Some(stroke) = &outcome.stroke {
        let p = opts.out.join("stroke.ron");
        stroke.save(&p)?;
        if let Some(extra) = &opts.record_stroke {
            stroke.save(extra)?;
        }
        stroke_path = Some(p.display().to_string());
    }
    let quant = |q| outcome.log.frame_ms_quantile(q);
    let latency = |q| outcome.log.latency_ms_quantile(q);
    let report = XrReport {
        scene: xr.scene_path().display().to_string(),
        headset: describe,
        solver_device: xr.body.device(),
        sim_mode: sim_mode.name().into(),
        sim_mode_why,
        frames: outcome.frames,
        rendered: outcome.rendered,
        sim_frames: outcome.sim_frames,
        session_states: outcome
            .session_states
            .iter()
            .map(|p| format!("{p:?}"))
            .collect(),
        released_tets: outcome.released_tets,
        cut_box: outcome.cut_box,
        max_tool_force: outcome.max_tool_force,
        max_haptic: outcome.max_haptic,
        haptic_pulses: outcome.haptic_pulses,
        haptic_stops: outcome.haptic_stops,
        dropped_time_s: outcome.dropped_time,
        display_hz: outcome.display_hz,
        dropped_frames: outcome.dropped_frames,
        sim_steps_per_s: if outcome.sim_wall_s > 0.0 {
            outcome.sim_frames as f64 / outcome.sim_wall_s
        } else {
            0.0
        },
        tool_latency_ms_p50_p95: latency(0.5).zip(latency(0.95)),
        slow_sim_ms: opts.slow_sim_ms,
        substeps: (xr.nominal_substeps(), outcome.min_substeps_used),
        frame_ms_p50_p95: quant(0.5).zip(quant(0.95)),
        solver_resets: outcome.solver_resets,
        exit: match (&outcome.error, outcome.exit) {
            (Some(e), _) => format!("failed: {e:#}"),
            (None, _) if outcome.interrupted => "Interrupted".into(),
            (None, Some(e)) => format!("{e:?}"),
            (None, None) => "the runtime never made the session ready".into(),
        },
        stroke: stroke_path,
        played_stroke: opts.stroke.as_ref().map(|p| p.display().to_string()),
        exercise: opts.exercise.as_ref().map(|p| p.display().to_string()),
        attempts: exercise.map(|e| e.attempts.clone()).unwrap_or_default(),
    };
    let json = serde_json::to_string_pretty(&report)?;
    let path = opts.out.join("xr_report.json");
    incise_sim::io::write_atomic(&path, json.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    match outcome.error.take() {
        Some(e) => Err(e.context(format!(
            "the XR session failed after {} display frames; the frame log, the stroke and xr_report.json in {} were kept",
            outcome.frames,
            opts.out.display()
        ))),
        // Ctrl-C: the session ended cleanly, but the run was cut short (exit 130).
        None if outcome.interrupted => Err(crate::interrupt::Interrupted {
            what: format!("the XR session on {}", report.scene),
            frames: outcome.frames,
            out: opts.out.display().to_string(),
        }
        .into()),
        None => Ok(report),
    }
}

impl XrReport {
    /// One line for the terminal.
    pub fn summary(&self) -> String {
        let latency = match self.tool_latency_ms_p50_p95 {
            Some((p50, p95)) => format!("{p50:.0}/{p95:.0} ms"),
            None => "-".into(),
        };
        format!(
            "{} display frames ({} rendered, {} dropped), {} simulation frames ({:.1}/s, {}), tool-to-tissue latency p50/p95 {}, {} tets released, tool force up to {:.2} N, exit {}",
            self.frames,
            self.rendered,
            self.dropped_frames,
            self.sim_frames,
            self.sim_steps_per_s,
            self.sim_mode,
            latency,
            self.released_tets,
            self.max_tool_force,
            self.exit
        )
    }
}
