//! The XR frame loop, the same for the OpenXR session and the simulated headset: per
//! display frame, controller input → tray and scalpel (or a recorded stroke in simulation
//! time), the pacer's simulation frames (fixed dt, substeps cut before time when late),
//! vibration from the contact force, both eyes rendered into the headset's targets, and a
//! frame-time row.

use std::time::Instant;

use anyhow::Result;
use glam::Mat4;
use incise_scalpel::{Stroke, StrokeRecorder};
use incise_sim::skin::Skin;
use incise_xr::frame::{ToolState, pinned_nodes};
use incise_xr::openxr::controls::{ControllerState, commands};
use incise_xr::openxr::eye::eye_view;
use incise_xr::openxr::haptics::{HapticCall, HapticGate, haptic_pulse};
use incise_xr::openxr::lifecycle::{ExitReason, SessionPhase};
use incise_xr::openxr::pacing::{FramePacer, PacingConfig};
use incise_xr::openxr::scalpel_pose::{BladeOffset, scalpel_pose};
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{FrameEvent, Headset, XrError};
use incise_xr::{BodyState, RenderSettings, Renderer};

use super::exercise::XrExercise;
use super::frame_log::{FrameLog, FrameRow};
use super::xr_body::XrBody;
use crate::screenshots::stress_scale;

/// Fraction of a display period the simulation may use.
pub const SIM_BUDGET: f64 = 0.5;
/// Most simulation frames stepped in one display frame.
pub const MAX_SIM_FRAMES: u32 = 3;
/// `Idle` answers in a row after which the loop gives up (about 10 s of a runtime that
/// never makes the session ready).
const MAX_IDLE: u32 = 1000;

/// How the loop runs.
pub struct LoopOptions<'a> {
    /// Stop after this many display frames (asks the session to exit).
    pub max_frames: Option<u64>,
    /// Where the blade sits on the right controller.
    pub blade: BladeOffset,
    /// Contact force (N) → vibration amplitude (0..1): the scalpel's haptic curve.
    pub haptic: &'a dyn Fn(f32) -> f32,
    /// Keep the scene's substeps whatever the measured cost.
    pub nominal_pacing: bool,
    /// Record the scalpel's path as a stroke.
    pub record: bool,
    /// The tray at the start.
    pub tray: Tray,
    /// Testing aid: a NaN in the solver just before this simulation frame of the session
    /// (the frame fails, is rolled back and the scene reset).
    pub inject_nan_at: Option<u64>,
    /// Drive the scalpel along this stroke (sim world, simulation time), engaged, instead
    /// of the right controller; the session ends when the stroke has been played.
    pub stroke: Option<&'a Stroke>,
}

/// What a session did.
pub struct LoopOutcome {
    /// Display frames run.
    pub frames: u64,
    /// Display frames rendered.
    pub rendered: u64,
    /// Simulation frames stepped.
    pub sim_frames: u64,
    /// Released tets at the end.
    pub released_tets: usize,
    /// Bounding box (min, max corners, sim world, m) of the released tets' rest
    /// centroids: where the cut is.
    pub cut_box: Option<super::xr_body::CutBox>,
    /// Largest tool contact force, N.
    pub max_tool_force: f32,
    /// Largest vibration amplitude sent.
    pub max_haptic: f32,
    /// Simulated time given up to keep the display on time, s.
    pub dropped_time: f64,
    /// Display refreshes the session's frames missed because a frame came late: the
    /// predicted display times of consecutive frames are this many nominal display
    /// periods more than one apart (a runtime may also stretch the period it predicts
    /// for a slow app; the nominal period is the shortest it predicted).
    pub dropped_frames: u64,
    /// The nominal display rate: the highest the runtime predicted, Hz.
    pub display_hz: f64,
    /// Wall time of the session loop, s.
    pub wall_s: f64,
    /// Fewest substeps used.
    pub min_substeps_used: u32,
    /// Times the solver failed and the scene was reset.
    pub solver_resets: u32,
    /// How the session ended (`None`: the runtime never made it ready).
    pub exit: Option<ExitReason>,
    /// Whether Ctrl-C (or SIGTERM) ended it.
    pub interrupted: bool,
    /// Vibration pulses sent (`xrApplyHapticFeedback`).
    pub haptic_pulses: u64,
    /// Vibration stops sent (`xrStopHapticFeedback`): one each time the blade left the
    /// tissue, and one at the end if it was still vibrating.
    pub haptic_stops: u64,
    /// The session states, in order.
    pub session_states: Vec<SessionPhase>,
    /// The scalpel's path, when recorded and the controller was tracked.
    pub stroke: Option<Stroke>,
    /// Per-frame times.
    pub log: FrameLog,
    /// The failure that stopped the session, when it did not end cleanly (the outputs
    /// above are still complete up to it).
    pub error: Option<anyhow::Error>,
}

/// Run the session on `headset` until it ends.
pub fn run_loop(
    headset: &mut dyn Headset,
    xr: &mut XrBody,
    skin: &Skin,
    opts: &LoopOptions<'_>,
    mut exercise: Option<&mut XrExercise>,
) -> Result<LoopOutcome> {
    let dev = headset.device().clone();
    let mut renderer = Renderer::new(
        &dev.device,
        &dev.queue,
        headset.format(),
        xr.solver().mesh(),
        skin,
    );
    let nominal = xr.nominal_substeps();
    let sim_dt = xr.solver().params().frame_dt as f64;
    let mut pacer = FramePacer::new(PacingConfig {
        sim_dt,
        nominal_substeps: nominal,
        min_substeps: if opts.nominal_pacing {
            nominal
        } else {
            xr.min_substeps()
        },
        budget_fraction: SIM_BUDGET,
        max_sim_frames: MAX_SIM_FRAMES,
    });
    let mut tray = opts.tray;
    let mut previous = ControllerState::default();
    let (mut paused, mut stress) = (false, false);
    let mut recorder = StrokeRecorder::new();
    let mut sim_time = 0.0f64;
    let mut out = LoopOutcome {
        frames: 0,
        rendered: 0,
        sim_frames: 0,
        released_tets: 0,
        cut_box: None,
        max_tool_force: 0.0,
        max_haptic: 0.0,
        dropped_time: 0.0,
        dropped_frames: 0,
        display_hz: 0.0,
        wall_s: 0.0,
        min_substeps_used: nominal,
        solver_resets: 0,
        exit: None,
        interrupted: false,
        haptic_pulses: 0,
        haptic_stops: 0,
        session_states: Vec::new(),
        stroke: None,
        log: FrameLog::default(),
        error: None,
    };
    let (background, background_alpha) = headset.backdrop().clear();
    let mut idle = 0;
    let mut exit_asked = false;
    let mut inject_nan_at = opts.inject_nan_at;
    let mut haptics = HapticGate::default();
    let session_start = Instant::now();
    // Every frame runs inside this closure so that a failure mid-frame still ends with
    // the stroke, the frame log and the report saved.
    let mut session = || -> Result<()> {
        if let Some(ex) = exercise.as_deref_mut() {
            ex.start(xr, skin, &dev)?;
        }
        if let Some(s) = opts.stroke {
            // The blade starts where the stroke does (as `incise run --stroke` places it).
            xr.drive_tool(Some(s.pose_at(0.0)), true)?;
        }
        loop {
            let frame = match headset.next_frame()? {
                FrameEvent::Ended(why) => {
                    out.exit = Some(why);
                    break;
                }
                FrameEvent::Idle => {
                    // Ctrl-C before the runtime runs the session (or between runs): the
                    // lifecycle ends a session that is not running at once.
                    if !exit_asked && crate::interrupt::requested() {
                        exit_asked = true;
                        out.interrupted = true;
                        headset.request_exit()?;
                    }
                    idle += 1;
                    if idle > MAX_IDLE {
                        break;
                    }
                    continue;
                }
                FrameEvent::Frame(f) => *f,
            };
            idle = 0;
            let started = Instant::now();
            let c = frame.controllers;
            let cmd = commands(&previous, &c);
            previous = c;
            if cmd.reset {
                // In an exercise, A first finishes an attempt the blade has touched (the
                // result card appears); otherwise it starts the scene over.
                let reset = match exercise.as_deref_mut() {
                    Some(ex) => ex.on_a(xr)?,
                    None => true,
                };
                if reset {
                    restart(xr, exercise.as_deref_mut(), skin, &dev)?;
                }
            }
            stress ^= cmd.toggle_stress;
            paused ^= cmd.toggle_pause;
            if let (true, Some(grip)) = (c.moving_tray(), c.left_grip) {
                tray = tray.placed_at(grip);
            }
            tray = tray.steered(c.stick, frame.display_period as f32);
            let engaged = opts.stroke.is_some() || c.blade_engaged();
            let tool_pose = c.right_grip.map(|g| scalpel_pose(g, opts.blade, &tray));

            // Simulation: the pacer's frames at the fixed dt, never waiting for the display.
            let mut plan = pacer.plan(frame.display_time, frame.display_period);
            if paused {
                plan.sim_frames = 0;
            }
            if plan.substeps != xr.solver().params().substeps {
                xr.set_substeps(plan.substeps)?;
            }
            let sim_start = Instant::now();
            let mut force = 0.0f32;
            let mut stepped = 0u64;
            for _ in 0..plan.sim_frames {
                // A stroke is played in simulation time: the pose at the end of this frame,
                // as `incise run --stroke` moves it.
                let tool_pose = match opts.stroke {
                    Some(s) => Some(s.pose_at(sim_time + sim_dt)),
                    None => tool_pose,
                };
                xr.drive_tool(tool_pose, engaged)?;
                if inject_nan_at == Some(out.sim_frames + stepped) {
                    inject_nan_at = None;
                    xr.body.inject_nan();
                }
                let stats = match xr.step() {
                    Ok(s) => s,
                    Err(e) => {
                        // The solver gave up (a tet inverted too long): the frame is rolled
                        // back; start the scene again rather than end the trainee's session.
                        eprintln!("xr: {e:#}; resetting the scene");
                        out.solver_resets += 1;
                        // The frame was rolled back: an attempt the blade touched is
                        // scored and saved as it stood, then a new one starts.
                        if let Some(ex) = exercise.as_deref_mut() {
                            ex.on_solver_failure(xr, &format!("{e:#}"))?;
                        }
                        restart(xr, exercise.as_deref_mut(), skin, &dev)?;
                        break;
                    }
                };
                sim_time += sim_dt;
                stepped += 1;
                if let Some(ex) = exercise.as_deref_mut() {
                    ex.after_step(&stats, tool_pose, sim_dt)?;
                }
                force = force.max(stats.tool_force.length());
                if let (true, Some(p)) = (opts.record, tool_pose) {
                    recorder.push(sim_time, p)?;
                }
            }
            let sim_ms = sim_start.elapsed().as_secs_f64() * 1e3;
            if plan.sim_frames > 0 {
                pacer.record(plan, sim_ms * 1e-3);
                out.min_substeps_used = out.min_substeps_used.min(plan.substeps);
            }
            out.sim_frames += stepped;
            out.max_tool_force = out.max_tool_force.max(force);

            let amplitude = (opts.haptic)(force);
            let pulse = haptic_pulse(amplitude, engaged, frame.display_period);
            match haptics.next(pulse) {
                HapticCall::Apply(p) => {
                    headset.vibrate(Some(p))?;
                    out.haptic_pulses += 1;
                }
                HapticCall::Stop => {
                    headset.vibrate(None)?;
                    out.haptic_stops += 1;
                }
                HapticCall::Nothing => {}
            }
            let sent = pulse.map_or(0.0, |p| p.amplitude);
            out.max_haptic = out.max_haptic.max(sent);

            // Both eyes into the headset's targets.
            let render_start = Instant::now();
            if frame.should_render {
                let targets = headset.acquire()?;
                let stage_from_sim = tray.stage_from_sim();
                let views = frame
                    .eyes
                    .map(|(pose, fov)| eye_view(pose, fov, stage_from_sim));
                let pinned = pinned_nodes(xr.solver());
                let (pose, tracked) = xr.tool();
                // The plan on the tissue and the result card above the tray.
                let (lines, panel) = match exercise.as_deref_mut() {
                    Some(ex) => {
                        let head = (frame.eyes[0].0.position + frame.eyes[1].0.position) * 0.5;
                        (ex.lines(xr), ex.panel(&mut renderer, &dev, &tray, head)?)
                    }
                    None => (Vec::new(), None),
                };
                let solver = xr.solver();
                let settings = RenderSettings {
                    lines,
                    panel,
                    stress_max: stress_scale(solver),
                    tool: ToolState {
                        transform: tracked
                            .then(|| Mat4::from_rotation_translation(pose.rotation, pose.position)),
                        spheres: vec![],
                    },
                    overlays: incise_xr::Overlays {
                        stress,
                        ..Default::default()
                    },
                    background,
                    background_alpha,
                    ..RenderSettings::default()
                };
                let mut enc = dev
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("xr frame"),
                    });
                renderer.prepare(&mut enc, &BodyState::of_solver(solver, &pinned), &settings);
                renderer.render(
                    &mut enc,
                    &[(views[0], &targets[0]), (views[1], &targets[1])],
                    headset.eye_size(),
                );
                dev.queue.submit([enc.finish()]);
                headset.end_frame(true)?;
                out.rendered += 1;
            } else {
                headset.end_frame(false)?;
            }
            out.log.rows.push(FrameRow {
                frame: out.frames,
                display_time: frame.display_time,
                sim_frames: plan.sim_frames,
                substeps: plan.substeps,
                sim_ms,
                render_ms: render_start.elapsed().as_secs_f64() * 1e3,
                frame_ms: started.elapsed().as_secs_f64() * 1e3,
                rendered: frame.should_render,
                engaged,
                tool_force: force,
                haptic: sent,
                display_period: frame.display_period,
            });
            out.frames += 1;
            // Ctrl-C ends the session the way the runtime expects (xrRequestExitSession),
            // so the stroke and report are saved as after any other end; so do the frame
            // limit and the end of a played stroke.
            let interrupted = crate::interrupt::requested();
            let stroke_done = opts.stroke.is_some_and(|s| sim_time >= s.end_time());
            if !exit_asked
                && (interrupted || stroke_done || opts.max_frames.is_some_and(|m| out.frames >= m))
            {
                exit_asked = true;
                out.interrupted = interrupted;
                headset.request_exit()?;
            }
        }
        Ok(())
    };

    let ended = session();
    out.wall_s = session_start.elapsed().as_secs_f64();
    (out.display_hz, out.dropped_frames) = out.log.missed_refreshes();
    // An attempt the blade touched is scored and saved however the session ended.
    let saved = match exercise {
        Some(ex) => ex.end_session(xr),
        None => Ok(()),
    };
    let ended = match (ended, saved) {
        (Ok(()), saved) => saved,
        (Err(e), Ok(())) => Err(e),
        (Err(e), Err(s)) => {
            eprintln!("xr: saving the attempt failed: {s:#}");
            Err(e)
        }
    };
    if let Err(e) = ended {
        match e.downcast_ref::<XrError>().and_then(XrError::lost) {
            // The runtime lost the session or is going away: a clean end, as on the
            // LOSS_PENDING event.
            Some(why) => {
                eprintln!("xr: {e:#}: the session is over");
                out.exit = Some(why);
            }
            None => out.error = Some(e),
        }
    }
    // The controller may be gone with the session: stopping its vibration can fail.
    if haptics.vibrating() {
        let _ = headset.vibrate(None);
        out.haptic_stops += 1;
    }
    out.session_states = headset.session_states().to_vec();
    out.dropped_time = pacer.dropped_time();
    (out.released_tets, out.cut_box) = xr.cut_extent();
    // A stroke needs two poses: a session that ended after one simulation frame (Ctrl-C
    // at once) has none to save, and its report is still written.
    if opts.record && recorder.len() >= 2 {
        out.stroke = Some(recorder.finish()?);
    }
    Ok(out)
}

/// The scene back to rest, and a new exercise attempt on it.
fn restart(
    xr: &mut XrBody,
    exercise: Option<&mut XrExercise>,
    skin: &Skin,
    dev: &incise_xr::RenderDevice,
) -> Result<()> {
    xr.reset()?;
    if let Some(ex) = exercise {
        ex.start(xr, skin, dev)?;
    }
    Ok(())
}
