//! The XR frame loop, the same for the OpenXR session and the simulated headset: per
//! display frame, controller input → tray and the tool command (the scalpel pose sampled
//! at the frame's predicted display time, trigger, reset, pause), the simulation
//! advanced (on its own thread, or stepped in the frame: [`super::sim_mode`]), vibration
//! from the contact force, both eyes rendered from the latest completed state into the
//! headset's targets, and a frame-time row.

use std::time::Instant;

use anyhow::{Result, bail};
use glam::Mat4;
use incise_scalpel::Stroke;
use incise_sim::skin::Skin;
use incise_xr::frame::ToolState;
use incise_xr::openxr::controls::{ControllerState, commands};
use incise_xr::openxr::eye::eye_view;
use incise_xr::openxr::haptics::{HapticCall, HapticGate, haptic_pulse};
use incise_xr::openxr::lifecycle::{ExitReason, SessionPhase};
use incise_xr::openxr::scalpel_pose::{BladeOffset, scalpel_pose};
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{FrameEvent, Headset, HeadsetFrame, XrError};
use incise_xr::{RenderDevice, RenderSettings, Renderer};

use super::exercise::XrExercise;
use super::frame_log::{FrameLog, FrameRow};
use super::in_frame::InFrameSim;
use super::sim_mode::SimMode;
use super::sim_source::{RenderInput, Sim, ThreadSim};
use super::sim_state::{Advanced, SimState, ToolCommand};
use super::sim_step::{SimFaults, SimStepper};
use super::sim_thread::{self, SimLink, ThreadConfig};
use super::xr_body::XrBody;

/// `Idle` answers in a row after which the loop gives up (about 10 s of a runtime that
/// never makes the session ready).
pub const MAX_IDLE: u32 = 1000;

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
    /// Drive the scalpel along this stroke (sim world, simulation time), engaged, instead
    /// of the right controller; the session ends when the stroke has been played.
    pub stroke: Option<&'a Stroke>,
    /// Where the solver is stepped.
    pub sim_mode: SimMode,
    /// Testing aids: a NaN before a simulation frame (rolled back, the scene reset), a
    /// panic, an artificially slow solver.
    pub faults: SimFaults,
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
    /// Simulated time given up to keep real time, s.
    pub dropped_time: f64,
    /// Wall time of the session loop, s.
    pub wall_s: f64,
    /// Wall time the simulation ran, s (the thread: from the first command).
    pub sim_wall_s: f64,
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

impl LoopOutcome {
    fn new(nominal_substeps: u32) -> Self {
        LoopOutcome {
            frames: 0,
            rendered: 0,
            sim_frames: 0,
            released_tets: 0,
            cut_box: None,
            max_tool_force: 0.0,
            dropped_time: 0.0,
            wall_s: 0.0,
            sim_wall_s: 0.0,
            min_substeps_used: nominal_substeps,
            solver_resets: 0,
            exit: None,
            interrupted: false,
            haptic_pulses: 0,
            haptic_stops: 0,
            session_states: Vec::new(),
            stroke: None,
            log: FrameLog::default(),
            error: None,
        }
    }
}

/// Run the session on `headset` until it ends.
pub fn run_loop(
    headset: &mut dyn Headset,
    xr: &mut XrBody,
    skin: &Skin,
    opts: &LoopOptions<'_>,
    exercise: Option<&mut XrExercise>,
) -> Result<LoopOutcome> {
    if opts.sim_mode == SimMode::Thread && exercise.is_some() {
        bail!("exercise sessions step the solver in the frame loop (--sim in-frame)");
    }
    let dev = headset.device().clone();
    let renderer = Renderer::new(
        &dev.device,
        &dev.queue,
        headset.format(),
        xr.solver().mesh(),
        skin,
    );
    let sim_dt = xr.solver().params().frame_dt as f64;
    let stepper = SimStepper::new(opts.stroke, sim_dt, opts.record, opts.faults);
    let mut display = Display {
        headset,
        renderer,
        dev,
        skin,
        opts,
        tray: opts.tray,
        previous: ControllerState::default(),
        paused: false,
        stress: false,
        haptics: HapticGate::default(),
        exit_asked: false,
        out: LoopOutcome::new(xr.nominal_substeps()),
    };
    let started = Instant::now();
    let (ended, exercise) = match opts.sim_mode {
        SimMode::InFrame => display.in_frame(xr, stepper, exercise),
        SimMode::Thread => (display.threaded(xr, stepper), exercise),
    };
    display.out.wall_s = started.elapsed().as_secs_f64();
    if opts.sim_mode == SimMode::InFrame {
        display.out.sim_wall_s = display.out.wall_s;
    }
    Ok(display.finish(ended, xr, exercise))
}

/// What a display frame showed: whether it rendered, the vibration amplitude sent, its
/// tool-to-tissue latency (ms, rendered frames).
struct Shown {
    rendered: bool,
    haptic: f32,
    tool_latency_ms: Option<f64>,
}

/// The display side of a session.
struct Display<'h, 'o> {
    headset: &'h mut dyn Headset,
    renderer: Renderer,
    dev: RenderDevice,
    skin: &'o Skin,
    opts: &'o LoopOptions<'o>,
    tray: Tray,
    previous: ControllerState,
    paused: bool,
    stress: bool,
    haptics: HapticGate,
    exit_asked: bool,
    out: LoopOutcome,
}

impl<'o> Display<'_, 'o> {
    /// The session with the solver stepped in each frame.
    fn in_frame<'e>(
        &mut self,
        xr: &mut XrBody,
        stepper: SimStepper<'o>,
        mut exercise: Option<&'e mut XrExercise>,
    ) -> (Result<()>, Option<&'e mut XrExercise>) {
        let mut s = InFrameSim::new(xr, stepper, self.opts.nominal_pacing);
        let mut sim = Sim::InFrame(&mut s);
        let ended = sim
            .start(exercise.as_deref_mut(), self.skin, &self.dev)
            .and_then(|()| self.frames(&mut sim, exercise.as_deref_mut()));
        // Kept however the session ended.
        self.out.sim_frames = s.stepper.frames;
        self.out.max_tool_force = s.stepper.max_force;
        self.out.solver_resets = s.stepper.failures;
        self.out.min_substeps_used = s.min_substeps;
        self.out.dropped_time = s.dropped_time();
        let recorded = s.stepper.recorded().map(|r| self.out.stroke = r);
        (ended.and(recorded), exercise)
    }

    /// The session with the solver on its own thread.
    fn threaded(&mut self, xr: &mut XrBody, stepper: SimStepper<'o>) -> Result<()> {
        let link = SimLink::default();
        // A state to show before the thread's first frame.
        link.states.put(SimState::capture(xr, None, true));
        let cfg = ThreadConfig {
            nominal_pacing: self.opts.nominal_pacing,
        };
        let shared = &link;
        std::thread::scope(|scope| {
            let thread = std::thread::Builder::new()
                .name("incise-sim".into())
                .spawn_scoped(scope, move || sim_thread::run(xr, shared, stepper, cfg))?;
            let mut t = ThreadSim::new(shared);
            let shown = self.frames(&mut Sim::Thread(&mut t), None);
            shared.stop();
            let t = match thread.join() {
                Ok(t) => t,
                // It catches its own panics; this would be one while saving its outcome.
                Err(_) => bail!("the simulation thread panicked"),
            };
            self.out.sim_frames = t.frames;
            self.out.max_tool_force = t.max_force;
            self.out.solver_resets = t.solver_resets;
            self.out.min_substeps_used = t.min_substeps_used;
            self.out.dropped_time = t.dropped_time;
            self.out.sim_wall_s = t.wall_s;
            self.out.stroke = t.stroke;
            // The thread's own failure comes first: the display only saw it stop.
            match shared.take_failure() {
                Some(e) => Err(e),
                None => shown,
            }
        })
    }

    /// Display frames until the session ends.
    fn frames(
        &mut self,
        sim: &mut Sim<'_, '_, '_>,
        mut exercise: Option<&mut XrExercise>,
    ) -> Result<()> {
        let mut idle = 0;
        loop {
            let frame = match self.headset.next_frame()? {
                FrameEvent::Ended(why) => {
                    self.out.exit = Some(why);
                    return Ok(());
                }
                FrameEvent::Idle => {
                    // Ctrl-C before the runtime runs the session (or between runs): the
                    // lifecycle ends a session that is not running at once.
                    if !self.exit_asked && crate::interrupt::requested() {
                        self.exit_asked = true;
                        self.out.interrupted = true;
                        self.headset.request_exit()?;
                    }
                    idle += 1;
                    if idle > MAX_IDLE {
                        return Ok(());
                    }
                    continue;
                }
                FrameEvent::Frame(f) => *f,
            };
            idle = 0;
            self.frame(&frame, sim, exercise.as_deref_mut())?;
        }
    }

    /// One display frame.
    fn frame(
        &mut self,
        frame: &HeadsetFrame,
        sim: &mut Sim<'_, '_, '_>,
        mut exercise: Option<&mut XrExercise>,
    ) -> Result<()> {
        let started = Instant::now();
        let cmd = self.input(frame, sim, exercise.as_deref_mut())?;
        let adv = sim.advance(frame, cmd, exercise.as_deref_mut(), self.skin, &self.dev)?;
        let sent = self.vibrate(adv.tool_force, cmd.engaged, frame.display_period)?;
        let render_start = Instant::now();
        let rendered = frame.should_render && self.render(frame, sim, exercise)?;
        if !rendered {
            self.headset.end_frame(false)?;
        }
        let shown = Shown {
            rendered,
            haptic: sent,
            tool_latency_ms: sim
                .shown_command()
                .filter(|_| rendered)
                .map(|(_, t)| (frame.display_time - t) * 1e3),
        };
        self.log(frame, &adv, &cmd, shown, [started, render_start]);
        self.maybe_exit(sim)
    }

    /// Controller input: the buttons, the tray, and the frame's tool command.
    fn input(
        &mut self,
        frame: &HeadsetFrame,
        sim: &mut Sim<'_, '_, '_>,
        exercise: Option<&mut XrExercise>,
    ) -> Result<ToolCommand> {
        let c = frame.controllers;
        let pressed = commands(&self.previous, &c);
        self.previous = c;
        if pressed.reset {
            sim.on_a(exercise, self.skin, &self.dev)?;
        }
        self.stress ^= pressed.toggle_stress;
        self.paused ^= pressed.toggle_pause;
        if let (true, Some(grip)) = (c.moving_tray(), c.left_grip) {
            self.tray = self.tray.placed_at(grip);
        }
        self.tray = self.tray.steered(c.stick, frame.display_period as f32);
        Ok(ToolCommand {
            frame: self.out.frames,
            display_time: frame.display_time,
            // Sampled by the headset at the predicted display time.
            pose: c
                .right_grip
                .map(|g| scalpel_pose(g, self.opts.blade, &self.tray)),
            engaged: self.opts.stroke.is_some() || c.blade_engaged(),
            paused: self.paused,
            resets: 0,
        })
    }

    /// The vibration for contact force `force`; the amplitude sent.
    fn vibrate(&mut self, force: f32, engaged: bool, period: f64) -> Result<f32> {
        let amplitude = (self.opts.haptic)(force);
        let pulse = haptic_pulse(amplitude, engaged, period);
        match self.haptics.send(pulse, |p| self.headset.vibrate(p))? {
            HapticCall::Apply(_) => self.out.haptic_pulses += 1,
            HapticCall::Stop => self.out.haptic_stops += 1,
            HapticCall::Nothing => {}
        }
        let sent = pulse.map_or(0.0, |p| p.amplitude);
        Ok(sent)
    }

    /// Both eyes into the headset's targets from the latest state; false when there is
    /// none to show (the frame is then ended without layers).
    fn render(
        &mut self,
        frame: &HeadsetFrame,
        sim: &mut Sim<'_, '_, '_>,
        exercise: Option<&mut XrExercise>,
    ) -> Result<bool> {
        // The plan on the tissue and the result card above the tray.
        let (lines, panel) = match (exercise, sim.body()) {
            (Some(ex), Some(xr)) => {
                let head = (frame.eyes[0].0.position + frame.eyes[1].0.position) * 0.5;
                let panel = ex.panel(&mut self.renderer, &self.dev, &self.tray, head)?;
                (ex.lines(xr), panel)
            }
            _ => (Vec::new(), None),
        };
        let Some(input) = sim.render_input() else {
            return Ok(false);
        };
        let targets = self.headset.acquire()?;
        let stage_from_sim = self.tray.stage_from_sim();
        let views = frame
            .eyes
            .map(|(pose, fov)| eye_view(pose, fov, stage_from_sim));
        let settings = self.settings(&input, lines, panel);
        let mut enc = self
            .dev
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("xr frame"),
            });
        self.renderer.prepare(&mut enc, &input.body, &settings);
        self.renderer.render(
            &mut enc,
            &[(views[0], &targets[0]), (views[1], &targets[1])],
            self.headset.eye_size(),
        );
        self.dev.queue.submit([enc.finish()]);
        self.headset.end_frame(true)?;
        self.out.rendered += 1;
        Ok(true)
    }

    fn settings(
        &self,
        input: &RenderInput<'_>,
        lines: Vec<incise_xr::SurfaceLine>,
        panel: Option<Mat4>,
    ) -> RenderSettings {
        let (background, background_alpha) = self.headset.backdrop().clear();
        let (pose, tracked) = input.tool;
        RenderSettings {
            lines,
            panel,
            stress_max: input.stress_max,
            tool: ToolState {
                transform: tracked
                    .then(|| Mat4::from_rotation_translation(pose.rotation, pose.position)),
                spheres: vec![],
            },
            overlays: incise_xr::Overlays {
                stress: self.stress,
                ..Default::default()
            },
            background,
            background_alpha,
            ..RenderSettings::default()
        }
    }

    /// The frame's row; `clock`: when the frame and its rendering started.
    fn log(
        &mut self,
        frame: &HeadsetFrame,
        adv: &Advanced,
        cmd: &ToolCommand,
        shown: Shown,
        clock: [Instant; 2],
    ) {
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        self.out.log.rows.push(FrameRow {
            frame: self.out.frames,
            display_time: frame.display_time,
            sim_frames: adv.sim_frames,
            substeps: adv.substeps,
            sim_ms: adv.sim_ms,
            render_ms: ms(clock[1]),
            frame_ms: ms(clock[0]),
            rendered: shown.rendered,
            engaged: cmd.engaged,
            tool_force: adv.tool_force,
            haptic: shown.haptic,
            display_period: frame.display_period,
            tool_latency_ms: shown.tool_latency_ms,
        });
        self.out.frames += 1;
    }

    /// Ctrl-C ends the session the way the runtime expects (xrRequestExitSession), so the
    /// stroke and report are saved as after any other end; so do the frame limit and the
    /// end of a played stroke.
    fn maybe_exit(&mut self, sim: &Sim<'_, '_, '_>) -> Result<()> {
        let interrupted = crate::interrupt::requested();
        let limit = self.opts.max_frames.is_some_and(|m| self.out.frames >= m);
        if !self.exit_asked && (interrupted || sim.stroke_done() || limit) {
            self.exit_asked = true;
            self.out.interrupted = interrupted;
            self.headset.request_exit()?;
        }
        Ok(())
    }

    /// The outcome, however the session `ended`.
    fn finish(
        self,
        ended: Result<()>,
        xr: &mut XrBody,
        exercise: Option<&mut XrExercise>,
    ) -> LoopOutcome {
        let Display {
            mut out,
            headset,
            haptics,
            ..
        } = self;
        // An attempt the blade touched is scored and saved however the session ended.
        let saved = match exercise {
            Some(ex) => ex.end_session(&xr.body),
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
        (out.released_tets, out.cut_box) = xr.cut_extent();
        out
    }
}
