//! `incise xr [SCENE]`: the scene on a tray in the room, cut with the right controller
//! (issue 7). With `--simulated-headset SCRIPT.ron` the same frame loop runs without a
//! runtime on a scripted headset, rendering both eyes offscreen. One display loop
//! ([`frame_loop`]) drives one session ([`session`]) for a body of any method, stepped
//! in the frame or on its own thread ([`stepper`], [`sim_thread`], [`live_sim`]).

pub mod command;
pub mod exercise;
pub mod frame_loop;
pub mod headset_bench;
pub mod headset_sim;
pub mod latest;
pub mod live_sim;
pub mod pacing;
pub mod session;
pub mod sim_mode;
pub mod sim_thread;
pub mod stepper;
pub mod unavailable;
pub mod xr_report;

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use glam::Vec3;
use incise_scalpel::{Stroke, ToolStroke};
use incise_xr::RenderDevice;
use incise_xr::openxr::scalpel_pose::BladeOffset;
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{Headset, XrSession};
use incise_xr::simulated::SimulatedHeadset;
use incise_xr::simulated::script::{HeadsetScript, Pacing, RightTrack};

use crate::scene::Method;
use crate::sim_body::{BodyView, DeviceChoice, OpenOptions};
use live_sim::{BodyOpener, LiveSim, SimFaults};
use session::{HeadsetExercise, SessionPlan};
use sim_mode::{SimChoice, SimMode};
pub use unavailable::XrUnavailable;
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
    /// Run the scene on this time integrator instead of its own (an XPBD-method scene;
    /// `incise bench realtime`'s headset table).
    pub scheme: Option<incise_sim::implicit::Scheme>,
}

/// Run `incise xr`; the session's summary line. No usable runtime: an [`XrUnavailable`]
/// error (exit 2).
pub fn run(opts: &XrOptions) -> Result<String> {
    let scene = match &opts.exercise {
        Some(e) => crate::exercise::exercise_scene(e)?,
        None => opts.scene.clone(),
    };
    if crate::scene::load_scene(&scene)?.model.method() != Method::Xpbd {
        refuse_xpbd_options(opts, &scene)?;
    }
    let exercise = (opts.exercise.as_ref())
        .map(|p| HeadsetExercise::open(p, &opts.out.join("attempts"), &opts.history))
        .transpose()?;
    let played = (opts.stroke.as_ref())
        .map(|p| {
            incise_scalpel::load_stroke(p).with_context(|| format!("--stroke {}", p.display()))
        })
        .transpose()?;
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    match &opts.simulated {
        Some(script) => run_simulated(opts, &scene, script, (exercise, played)),
        None => {
            let mut session = open_session(&scene)?;
            eprintln!("xr: backdrop {:?}", session.backdrop());
            let dev = session.device().clone();
            let mode = sim_mode::resolve(opts.sim, exercise.is_some(), false)?;
            let live = open_body(opts, &scene, (mode.0, opts.device, &dev), played)?;
            let first = live.view(None);
            let plan = plan(opts, &scene, mode, (tray_for(&first), false), exercise);
            session::run(&mut session, (live, first), plan)
        }
    }
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

/// The body of `scene` for a session: a hand on its tool (or `played` as its stroke),
/// on the device `opts` asks (a GPU body on the simulation thread's own device when the
/// body is stepped there), its path recorded for `incise run --stroke` where the body
/// replays strokes.
fn open_body(
    opts: &XrOptions,
    scene: &Path,
    (mode, device, dev): (SimMode, DeviceChoice, &RenderDevice),
    played: Option<Stroke>,
) -> Result<LiveSim> {
    let gpu = match device {
        DeviceChoice::Cpu => None,
        _ => Some(solver_device(device, mode, dev)?.compute_context()),
    };
    let opener = BodyOpener {
        scene: scene.to_path_buf(),
        opts: OpenOptions {
            device,
            gpu,
            stroke: opts.stroke.clone(),
            hand: played.is_none(),
            scheme: opts.scheme,
            quiet: true,
            ..OpenOptions::default()
        },
    };
    let faults = SimFaults {
        nan_at: opts.inject_nan_at,
        panic_at: opts.inject_sim_panic_at,
        slow: Duration::from_millis(opts.slow_sim_ms),
    };
    let live = LiveSim::open(opener, played, faults)?;
    // A stroke is recorded where `incise run --stroke` can replay it (an XPBD body).
    let record = live.body.body.solver_parts().is_some();
    Ok(if record { live.recording() } else { live })
}

/// The tray that holds the body drawn in `view` (its first frame).
fn tray_for(view: &BodyView) -> Tray {
    let positions = match view {
        BodyView::Tets(t) => &t.positions,
        BodyView::Cut(c) => &c.positions,
    };
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    Tray::for_bounds(lo, hi)
}

/// How the session runs: `mode` (and why), the tray and whether the script asks for the
/// scene's substeps always.
fn plan(
    opts: &XrOptions,
    scene: &Path,
    mode: (SimMode, String),
    (tray, nominal_script): (Tray, bool),
    exercise: Option<HeadsetExercise>,
) -> SessionPlan {
    SessionPlan {
        scene: scene.to_path_buf(),
        out: opts.out.clone(),
        mode,
        // A played stroke keeps the scene's substeps, so its recording replays with
        // `incise run --stroke` through the same physics.
        nominal: nominal_script || opts.stroke.is_some(),
        frames: opts.frames,
        tray,
        played: opts.stroke.clone(),
        record_stroke: opts.record_stroke.clone(),
        slow_ms: opts.slow_sim_ms,
        exercise,
        exercise_file: opts.exercise.clone(),
    }
}

fn run_simulated(
    opts: &XrOptions,
    scene: &Path,
    script_path: &Path,
    (exercise, played): (Option<HeadsetExercise>, Option<Stroke>),
) -> Result<String> {
    let script = HeadsetScript::load(script_path)?;
    let dev = RenderDevice::headless()?;
    let device = match opts.device {
        DeviceChoice::Auto => DeviceChoice::Cpu,
        d => d,
    };
    let mode = sim_mode::resolve(opts.sim, exercise.is_some(), !script.realtime)?;
    let live = open_body(opts, scene, (mode.0, device, &dev), played)?;
    let first = live.view(None);
    let tray = tray_for(&first);
    let stroke = match &script.right {
        Some(RightTrack::Tool { stroke, .. }) => Some(match stroke {
            ToolStroke::File(f) => incise_scalpel::load_stroke(
                &script_path.parent().unwrap_or(Path::new(".")).join(f),
            )?,
            ToolStroke::Incision(i) => i
                .stroke(&live.body.scalpel()?)
                .with_context(|| format!("{}: right.stroke", script_path.display()))?,
        }),
        _ => None,
    };
    let nominal = script.pacing == Pacing::Nominal;
    let mut headset =
        SimulatedHeadset::new(script, stroke, tray, BladeOffset::default(), dev, &opts.out)?;
    let plan = plan(opts, scene, mode, (tray, nominal), exercise);
    session::run(&mut headset, (live, first), plan)
}
