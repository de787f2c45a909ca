//! `incise xr [SCENE]`: the scene on a tray in the room, cut with the right controller
//! (issue 7). With `--simulated-headset SCRIPT.ron` the same frame loop runs without a
//! runtime on a scripted headset, rendering both eyes offscreen. One display loop
//! ([`frame_loop`]) drives every method's session: XPBD's ([`xpbd_session`]) and the
//! others' ([`method_session`]), through [`headset_sim::HeadsetSim`].

pub mod exercise;
pub mod frame_log;
pub mod frame_loop;
pub mod headset_sim;
pub mod in_frame;
pub mod latest;
pub mod method_session;
pub mod method_stepper;
pub mod method_thread;
pub mod script;
pub mod sim_mode;
pub mod sim_source;
pub mod sim_state;
pub mod sim_step;
pub mod sim_thread;
pub mod simulated;
pub mod unavailable;
pub mod xpbd_session;
pub mod xr_body;
pub mod xr_report;

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use incise_scalpel::HapticCurve;
use incise_xr::RenderDevice;
use incise_xr::openxr::scalpel_pose::BladeOffset;
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{Headset, XrSession};

use crate::scene::Method;
use crate::sim_body::DeviceChoice;
use exercise::XrExercise;
use script::{HeadsetScript, Pacing, RightTrack};
use sim_mode::{SimChoice, SimMode};
use sim_step::SimFaults;
use simulated::SimulatedHeadset;
pub use unavailable::XrUnavailable;
use xpbd_session::{LoopOptions, LoopOutcome, run_loop};
use xr_body::XrBody;
pub use xr_report::XrReport;

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

/// Run `incise xr`; the session's summary line. A scene of another method than XPBD runs
/// a [`method_session`] (a Nakao scene's exercise too). No usable runtime: an
/// [`XrUnavailable`] error (exit 2).
pub fn run(opts: &XrOptions) -> Result<String> {
    let scene = match &opts.exercise {
        Some(e) => crate::exercise::exercise_scene(e)?,
        None => opts.scene.clone(),
    };
    if crate::scene::load_scene(&scene)?.model.method() != Method::Xpbd {
        return run_method(opts, &scene);
    }
    run_xpbd(opts).map(|r| r.summary())
}

/// `incise xr` for a Nakao or rheology `scene` (a Nakao exercise's, with `--exercise`), on
/// the simulated headset or the runtime's.
fn run_method(opts: &XrOptions, scene: &Path) -> Result<String> {
    let exercise = opts
        .exercise
        .as_ref()
        .map(|p| {
            method_session::HeadsetExercise::open(p, &opts.out.join("attempts"), &opts.history)
        })
        .transpose()?;
    refuse_xpbd_options(opts, scene)?;
    let sim = method_session::MethodSim {
        choice: opts.sim,
        slow: Duration::from_millis(opts.slow_sim_ms),
        frames: opts.frames,
    };
    if let Some(script) = &opts.simulated {
        return method_session::run_simulated(scene, script, &opts.out, &sim, exercise);
    }
    let mut session = open_session(scene)?;
    method_session::run_on_runtime(&mut session, scene, &opts.out, &sim, exercise)
}

/// The options only an XPBD session uses, refused for a method session's `scene` (naming
/// the option) rather than ignored.
fn refuse_xpbd_options(opts: &XrOptions, scene: &Path) -> Result<()> {
    let given = [
        (opts.stroke.is_some(), "--stroke"),
        (opts.record_stroke.is_some(), "--record-stroke"),
        (opts.device == DeviceChoice::Gpu, "--device gpu"),
        (opts.inject_nan_at.is_some(), "--inject-nan-at"),
        (opts.inject_sim_panic_at.is_some(), "--inject-sim-panic-at"),
    ];
    match given.iter().find(|(on, _)| *on) {
        Some((_, flag)) => bail!(
            "{}: {flag} is for XPBD scenes; this scene's body runs on the CPU and its tool \
             follows the scene's script or the right controller",
            scene.display()
        ),
        None => Ok(()),
    }
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
    eprintln!("xr: {}", headset.describe());
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
    let mut stroke_path = None;
    if let Some(stroke) = &outcome.stroke {
        let p = opts.out.join("stroke.ron");
        stroke.save(&p)?;
        if let Some(extra) = &opts.record_stroke {
            stroke.save(extra)?;
        }
        stroke_path = Some(p.display().to_string());
    }
    let report = XrReport {
        scene: xr.scene_path().display().to_string(),
        solver_device: xr.body.device(),
        sim_mode: sim_mode.name().into(),
        sim_mode_why,
        sim_frames: outcome.sim_frames,
        released_tets: Some(outcome.released_tets),
        cut_box: outcome.cut_box,
        max_tool_force: outcome.max_tool_force,
        haptic_pulses: outcome.display.haptic_pulses,
        haptic_stops: outcome.display.haptic_stops,
        dropped_time_s: outcome.dropped_time,
        sim_steps_per_s: if outcome.sim_wall_s > 0.0 {
            outcome.sim_frames as f64 / outcome.sim_wall_s
        } else {
            0.0
        },
        slow_sim_ms: opts.slow_sim_ms,
        substeps: Some((xr.nominal_substeps(), outcome.min_substeps_used)),
        solver_resets: Some(outcome.solver_resets),
        exit: xr_report::exit_text(
            outcome.display.error.as_ref(),
            outcome.display.interrupted,
            outcome.display.exit,
        ),
        stroke: stroke_path,
        played_stroke: opts.stroke.as_ref().map(|p| p.display().to_string()),
        exercise: opts.exercise.as_ref().map(|p| p.display().to_string()),
        attempts: exercise.map(|e| e.attempts.clone()).unwrap_or_default(),
        ..XrReport::new(Method::Xpbd, &outcome.display.log, headset)
    };
    report.save(&outcome.display.log, &opts.out)?;
    match outcome.display.error.take() {
        Some(e) => Err(xr_report::failed(
            e,
            outcome.display.frames,
            "the frame log, the stroke and xr_report.json",
            &opts.out,
        )),
        // Ctrl-C: the session ended cleanly, but the run was cut short (exit 130).
        None if outcome.display.interrupted => Err(xr_report::interrupted(
            &report.scene,
            outcome.display.frames,
            &opts.out,
        )),
        None => Ok(report),
    }
}
