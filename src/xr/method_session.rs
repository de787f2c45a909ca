//! The headset session for a scene of any method: the organ on the tray, its body stepped
//! on its own thread ([`MethodThread`], the default on a real-time headset: the display
//! draws the newest completed frame and never waits) or inside each display frame up to
//! the frame's display time (a simulated headset's virtual clock, or `--sim in-frame`),
//! with the scene's own script (the Nakao blade's stroke, the rheology indenter) until the
//! right controller's trigger takes the tool: then the scalpel cuts (Nakao) or presses
//! (rheology) where the controller holds it, vibrating with the method's tool force where
//! it has one. Both eyes show the heat map of the method's own quantity. Writes the body's
//! `report.json` (the run's schema) into the output folder, and the session's frame log
//! (`frames.csv`) and `xr_report.json` as an XPBD session does (also when it fails).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use glam::{Quat, Vec3};
use incise_scalpel::HapticCurve;
use incise_sim::contact::ToolPose;
use incise_xr::openxr::controls::{ControllerState, commands};
use incise_xr::openxr::haptics::{HapticCall, HapticGate, haptic_pulse};
use incise_xr::openxr::lifecycle::ExitReason;
use incise_xr::openxr::scalpel_pose::{BladeOffset, scalpel_pose};
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{FrameEvent, Headset, HeadsetFrame, eye::eye_view};
use incise_xr::{Overlays, RenderDevice, RenderSettings, Renderer};

use super::exercise::XrExercise;
use super::frame_log::{FrameLog, FrameRow};
use super::frame_loop::MAX_IDLE;
use super::method_stepper::Stepper;
use super::script::{HeadsetScript, RightTrack};
use super::sim_mode::{self, SimChoice, SimMode};
use super::simulated::SimulatedHeadset;
use super::xr_report::{self, XrReport};
use crate::bench::soak::percentile;
use crate::exercise::ToolFrame;
use crate::pictures::tet_drawing::TetDrawing;
use crate::sim_body::ToolInput;
use crate::sim_body::recorded::RecordedBody;

/// Where a method session steps its body, and a slowdown per body frame (testing aid).
#[derive(Debug, Clone)]
pub struct MethodSim {
    /// `--sim`: a thread (the default on a real-time headset) or in the frame.
    pub choice: SimChoice,
    /// Sleep this long after every body frame.
    pub slow: Duration,
    /// Ask the runtime to end the session after this many display frames (`--frames`).
    pub frames: Option<u64>,
}

/// What a method session did.
struct Session {
    stepper: Stepper,
    drawing: TetDrawing,
    renderer: Renderer,
    tray: Tray,
    /// Whether the controller has taken the tool from the scene's script.
    hand: bool,
    /// The display time of the first frame, s (simulated time 0).
    start: Option<f64>,
    /// Vibration pulses sent.
    pulses: u64,
    /// Vibration stops sent (once each time the blade stopped vibrating).
    stops: u64,
    haptic: HapticCurve,
    /// Whether the controller is vibrating (a stop is sent once when it should stop).
    gate: HapticGate,
    /// One row per display frame.
    log: FrameLog,
    /// Simulated time given up by an in-frame body slower than real time, s.
    given_up: f64,
    /// Why the runtime ended the session, once it has.
    exit: Option<ExitReason>,
    /// Whether Ctrl-C asked the session to end.
    interrupted: bool,
    /// A Nakao exercise: its plan drawn, attempts recorded from the controller and
    /// scored on the body's cut surface (the body stepped in the frame).
    exercise: Option<MethodExercise>,
}

/// A method session's exercise, with what it needs to reload the scene for a new attempt.
pub struct MethodExercise {
    /// The exercise and its attempts.
    pub live: XrExercise<RecordedBody>,
    /// The controllers as of the last display frame (A is acted on when pressed).
    previous: ControllerState,
    /// The blade's last tracked pose (held, lifted, while the controller is untracked).
    pose: ToolPose,
    /// Where the session writes and how its body frames are slowed: what a new attempt's
    /// fresh body is opened with.
    reload: (PathBuf, Duration),
}

impl MethodExercise {
    /// Open the exercise at `path`, attempts saved under `out_root` and appended to
    /// `history`.
    pub fn open(path: &Path, out_root: &Path, history: &Path) -> Result<MethodExercise> {
        Ok(MethodExercise {
            live: XrExercise::open(path, out_root, history)?,
            previous: ControllerState::default(),
            // Out of reach until the controller is tracked.
            pose: ToolPose {
                position: Vec3::new(0.0, 0.0, 1.0),
                rotation: Quat::IDENTITY,
            },
            reload: (PathBuf::new(), Duration::ZERO),
        })
    }
}

/// Run `scene` (any method but XPBD) on the simulated headset playing `script_path`,
/// writing eye images, `report.json`, `frames.csv` and `xr_report.json` to `out`; the
/// session's summary line.
pub fn run_simulated(
    scene: &Path,
    script_path: &Path,
    out: &Path,
    sim: &MethodSim,
    exercise: Option<MethodExercise>,
) -> Result<String> {
    let script = HeadsetScript::load(script_path)?;
    let (mode, why) = sim_mode::resolve(sim.choice, exercise.is_some(), !script.realtime)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let (stepper, drawing) = Stepper::open(scene, out, mode, sim.slow)?;
    let tray = tray_for(&drawing);
    let stroke = tool_stroke(&script, script_path)?;
    let dev = RenderDevice::headless()?;
    let offset = BladeOffset::default();
    let mut headset = SimulatedHeadset::new(script, stroke, tray, offset, dev, out)?;
    run_on(
        &mut headset,
        scene,
        (stepper, drawing, exercise),
        tray,
        out,
        (mode, why),
        sim,
    )
}

/// Run `scene` (any method but XPBD) on the runtime's `headset` (real time: the body on
/// its own thread unless `sim` says otherwise), writing `report.json`, `frames.csv` and
/// `xr_report.json` to `out`; the session's summary line.
pub fn run_on_runtime(
    headset: &mut dyn Headset,
    scene: &Path,
    out: &Path,
    sim: &MethodSim,
    exercise: Option<MethodExercise>,
) -> Result<String> {
    let (mode, why) = sim_mode::resolve(sim.choice, exercise.is_some(), false)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let (stepper, drawing) = Stepper::open(scene, out, mode, sim.slow)?;
    let tray = tray_for(&drawing);
    let opened = (stepper, drawing, exercise);
    run_on(headset, scene, opened, tray, out, (mode, why), sim)
}

/// The tray that holds the body of `drawing`.
fn tray_for(drawing: &TetDrawing) -> Tray {
    let (lo, hi) = drawing.render.mesh.rest_bounds();
    Tray::for_bounds(lo, hi)
}

/// Run the opened body of `scene` (from [`Stepper::open`]) on `headset` with the organ on
/// `tray` (ending it after `sim.frames` display frames, if given); the body's
/// `report.json`, `frames.csv` and `xr_report.json` written to `out` (the last two also
/// when the session fails); the session's summary line, saying where the body was
/// stepped (`mode`, and why) and what a display frame cost.
fn run_on(
    headset: &mut dyn Headset,
    scene: &Path,
    (stepper, drawing, exercise): (Stepper, TetDrawing, Option<MethodExercise>),
    tray: Tray,
    out: &Path,
    (mode, why): (SimMode, String),
    sim: &MethodSim,
) -> Result<String> {
    let dev = headset.device().clone();
    let renderer = renderer_for(&dev, headset.format(), &drawing);
    let mut s = Session {
        stepper,
        drawing,
        renderer,
        tray,
        hand: false,
        start: None,
        pulses: 0,
        stops: 0,
        haptic: HapticCurve::default(),
        gate: HapticGate::default(),
        log: FrameLog::default(),
        given_up: 0.0,
        exit: None,
        interrupted: false,
        exercise,
    };
    if let Some(ex) = &mut s.exercise {
        ex.reload = (out.to_path_buf(), sim.slow);
    }
    s.start_attempt()?;
    let started = Instant::now();
    let ended = s.run(headset, &dev, sim.frames);
    // The controller may be gone with the session: stopping its vibration can fail.
    if s.gate.vibrating() && headset.vibrate(None).is_ok() {
        s.stops += 1;
    }
    let wall_s = started.elapsed().as_secs_f64();
    let report = s.report(headset, scene, (mode, why.clone()), sim.slow)?;
    let (p50, p95) = s.work_p50_p95();
    let (report, summary) = s.close(ended, report, wall_s, out)?;
    Ok(format!(
        "{} on {}: {} display frames ({} rendered), {} vibration pulses, \
         body stepped {} ({why}), display frame work p50 {p50:.2} ms, p95 {p95:.2} ms; {summary}",
        scene.display(),
        report.headset,
        report.frames,
        report.rendered,
        report.haptic_pulses,
        mode.name(),
    ))
}

/// The scripted right-hand stroke, drawn with the built-in scalpel.
fn tool_stroke(script: &HeadsetScript, path: &Path) -> Result<Option<incise_scalpel::Stroke>> {
    let Some(RightTrack::Tool { stroke, .. }) = &script.right else {
        return Ok(None);
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(Some(match stroke {
        crate::scene::ToolStroke::File(f) => incise_scalpel::load_stroke(&dir.join(f))?,
        crate::scene::ToolStroke::Incision(i) => {
            crate::scene::incision(&crate::scene::hand_tool::default_tool()?, i)
                .with_context(|| format!("{}: right.stroke", path.display()))?
        }
    }))
}

impl Session {
    /// An exercise's attempt on the body as loaded (frame 0).
    fn start_attempt(&mut self) -> Result<()> {
        let Some(ex) = &mut self.exercise else {
            return Ok(());
        };
        let Stepper::InFrame { body, .. } = &mut self.stepper else {
            bail!("exercise sessions step the body in the frame loop (--sim in-frame)");
        };
        ex.live.start(body)
    }

    /// A pressed in an exercise: an attempt the blade touched is finished (its card
    /// shown); otherwise the scene is loaded afresh and a new attempt starts.
    fn on_a(&mut self, headset: &dyn Headset, dev: &RenderDevice) -> Result<()> {
        let (Some(ex), Stepper::InFrame { body, .. }) = (&mut self.exercise, &self.stepper) else {
            return Ok(());
        };
        if !ex.live.on_a(body)? {
            return Ok(());
        }
        let scene = ex.live.exercise().scene_path.clone();
        let (out, slow) = ex.reload.clone();
        (self.stepper, self.drawing) = Stepper::open(&scene, &out, SimMode::InFrame, slow)?;
        self.renderer = renderer_for(dev, headset.format(), &self.drawing);
        ex.live.renderer_replaced();
        // The fresh body's time 0 is the next display frame's.
        (self.start, self.given_up) = (None, 0.0);
        self.start_attempt()
    }

    /// Keep body frame `b` for the attempt under way, stepped with `tool` (its pose
    /// recorded when the controller tracked it: `tracked`).
    fn keep(
        ex: &mut MethodExercise,
        b: &RecordedBody,
        tool: &ToolInput,
        tracked: bool,
    ) -> Result<()> {
        let (Some(frame), ToolInput::Hand { pose, .. }) = (b.last_frame(), tool) else {
            return Ok(());
        };
        let pose = tracked.then_some(*pose);
        ex.live
            .after_step(ToolFrame::of(frame), pose, b.body.frame_dt())
    }

    /// Display frames until the session ends, asking the runtime to end it after
    /// `max_frames` or on Ctrl-C (as the XPBD loop does, so the files are saved as after
    /// any other end).
    fn run(
        &mut self,
        headset: &mut dyn Headset,
        dev: &RenderDevice,
        max_frames: Option<u64>,
    ) -> Result<()> {
        let mut exit_asked = false;
        while let Some(frame) = self.next(headset, &mut exit_asked)? {
            self.frame(headset, dev, &frame)?;
            let limit = max_frames.is_some_and(|m| self.log.rows.len() as u64 >= m);
            self.maybe_exit(headset, &mut exit_asked, limit)?;
        }
        Ok(())
    }

    /// Ask the runtime to end the session once: on Ctrl-C, or when `limit` is reached.
    fn maybe_exit(
        &mut self,
        headset: &mut dyn Headset,
        asked: &mut bool,
        limit: bool,
    ) -> Result<()> {
        let interrupted = crate::interrupt::requested();
        if !*asked && (interrupted || limit) {
            *asked = true;
            self.interrupted = interrupted;
            headset.request_exit()?;
        }
        Ok(())
    }

    /// The next begun frame, `None` when the session has ended (the runtime's reason kept)
    /// or the runtime answered Idle [`MAX_IDLE`] times in a row.
    fn next(
        &mut self,
        headset: &mut dyn Headset,
        asked: &mut bool,
    ) -> Result<Option<HeadsetFrame>> {
        for _ in 0..=MAX_IDLE {
            match headset.next_frame()? {
                FrameEvent::Frame(f) => return Ok(Some(*f)),
                // Ctrl-C before the runtime runs the session ends it at once.
                FrameEvent::Idle => self.maybe_exit(headset, asked, false)?,
                FrameEvent::Ended(why) => {
                    self.exit = Some(why);
                    return Ok(None);
                }
            }
        }
        Ok(None)
    }

    /// Close the body after the session `ended` (its `report.json` written unless the
    /// session failed), then write `frames.csv` and `report` (completed with the body
    /// frames stepped, their rate over `wall_s` and how the session ended) into `out`,
    /// also on a failure; the report and the body's summary line.
    fn close(
        mut self,
        ended: Result<()>,
        mut report: XrReport,
        wall_s: f64,
        out: &Path,
    ) -> Result<(XrReport, String)> {
        let saved = match (&mut self.exercise, &self.stepper) {
            (Some(ex), Stepper::InFrame { body, .. }) => ex.live.end_session(body),
            _ => Ok(()),
        };
        let closed = ended.and(saved).and_then(|()| self.stepper.close(out));
        if let Ok((_, frames)) = &closed {
            report.sim_frames = *frames as u64;
        }
        if wall_s > 0.0 {
            report.sim_steps_per_s = report.sim_frames as f64 / wall_s;
        }
        report.exit = xr_report::exit_text(closed.as_ref().err(), self.interrupted, self.exit);
        report.save(&self.log, out)?;
        let kept = "the frame log and xr_report.json";
        match closed {
            // Ctrl-C: the session ended cleanly, but the run was cut short (exit 130).
            Ok(_) if self.interrupted => {
                Err(xr_report::interrupted(&report.scene, report.frames, out))
            }
            Ok((summary, _)) => Ok((report, summary)),
            Err(e) => Err(xr_report::failed(e, report.frames, kept, out)),
        }
    }

    /// Median and 95th percentile of the display frames' own work (stepping, vibration,
    /// drawing), ms.
    fn work_p50_p95(&self) -> (f64, f64) {
        let mut ms: Vec<f64> = self.log.rows.iter().map(|r| r.frame_ms).collect();
        ms.sort_by(f64::total_cmp);
        (percentile(&ms, 0.5), percentile(&ms, 0.95))
    }

    /// The session's `xr_report.json` so far: `scene` on `headset`, stepped `mode` (why),
    /// each body frame slowed by `slow`, the frames stepped as many as published.
    fn report(
        &self,
        headset: &dyn Headset,
        scene: &Path,
        (mode, why): (SimMode, String),
        slow: Duration,
    ) -> Result<XrReport> {
        let (method, solver_device) = self.stepper.body()?;
        let rows = &self.log.rows;
        Ok(XrReport {
            scene: scene.display().to_string(),
            solver_device,
            sim_mode: mode.name().into(),
            sim_mode_why: why,
            sim_frames: self.stepper.frames() as u64,
            max_tool_force: rows.iter().map(|r| r.tool_force).fold(0.0, f32::max),
            haptic_pulses: self.pulses,
            haptic_stops: self.stops,
            dropped_time_s: self.given_up,
            slow_sim_ms: slow.as_millis() as u64,
            exercise: (self.exercise.as_ref())
                .map(|e| e.live.exercise().path.display().to_string()),
            attempts: self
                .exercise
                .as_ref()
                .map_or(Vec::new(), |e| e.live.attempts.clone()),
            ..XrReport::new(method, &self.log, headset)
        })
    }

    /// One display frame: step the body up to the frame's display time with the tool,
    /// vibrate, draw both eyes, log the frame's row (also when ending the frame failed).
    fn frame(
        &mut self,
        headset: &mut dyn Headset,
        dev: &RenderDevice,
        f: &HeadsetFrame,
    ) -> Result<()> {
        let started = Instant::now();
        if let Some(ex) = &mut self.exercise {
            let pressed = commands(&ex.previous, &f.controllers);
            ex.previous = f.controllers;
            if pressed.reset {
                self.on_a(headset, dev)?;
            }
        }
        let start = *self.start.get_or_insert(f.display_time);
        let tool = self.tool(f);
        let stamp = (self.log.rows.len() as u64, f.display_time);
        let until = f.display_time - start - self.given_up;
        let tracked = f.controllers.right_grip.is_some();
        let ex = &mut self.exercise;
        let step = self
            .stepper
            .advance(tool, until, stamp, &mut |b| match ex {
                Some(ex) => Session::keep(ex, b, &tool, tracked),
                None => Ok(()),
            })?;
        self.given_up += step.given_up;
        if let Some(view) = step.view
            && self.drawing.update(view)?
        {
            // The topology changed (the new renderer needs the card again).
            self.renderer = renderer_for(dev, headset.format(), &self.drawing);
            if let Some(ex) = &mut self.exercise {
                ex.live.renderer_replaced();
            }
        }
        let adv = step.done;
        let haptic = self.vibrate(headset, adv.tool_force, f.display_period)?;
        let render_start = Instant::now();
        // A frame the runtime fails to end is still logged: its body frames were stepped.
        let ended = if f.should_render {
            self.render(headset, dev, f)
        } else {
            headset.end_frame(false).map_err(anyhow::Error::from)
        };
        let rendered = f.should_render && ended.is_ok();
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        self.log.rows.push(FrameRow {
            frame: stamp.0,
            display_time: f.display_time,
            sim_frames: adv.sim_frames,
            substeps: adv.substeps,
            sim_ms: adv.sim_ms,
            render_ms: ms(render_start),
            frame_ms: ms(started),
            rendered,
            engaged: f.controllers.blade_engaged(),
            tool_force: adv.tool_force,
            haptic,
            display_period: f.display_period,
            tool_latency_ms: (self.stepper.last_command())
                .filter(|_| rendered)
                .map(|(_, t)| (f.display_time - t) * 1e3),
        });
        ended
    }

    /// Vibrate with the tool force `force`, N, while the controller holds the tool; the
    /// amplitude sent.
    fn vibrate(&mut self, headset: &mut dyn Headset, force: f32, period: f64) -> Result<f32> {
        let pulse = haptic_pulse(self.haptic.amplitude(force), self.hand, period);
        match self.gate.send(pulse, |p| headset.vibrate(p))? {
            HapticCall::Apply(_) => self.pulses += 1,
            HapticCall::Stop => self.stops += 1,
            HapticCall::Nothing => {}
        }
        Ok(pulse.map_or(0.0, |p| p.amplitude))
    }

    /// Both eyes, drawn from the body's newest frame.
    fn render(
        &mut self,
        headset: &mut dyn Headset,
        dev: &RenderDevice,
        f: &HeadsetFrame,
    ) -> Result<()> {
        let targets = headset.acquire()?;
        let stage_from_sim = self.tray.stage_from_sim();
        let views = f
            .eyes
            .map(|(pose, fov)| eye_view(pose, fov, stage_from_sim));
        let (background, background_alpha) = headset.backdrop().clear();
        let (lines, panel) = match &mut self.exercise {
            Some(ex) => {
                let head = (f.eyes[0].0.position + f.eyes[1].0.position) * 0.5;
                let panel = ex.live.panel(&mut self.renderer, dev, &self.tray, head)?;
                let line = ex.live.decal().line(self.drawing.state().positions);
                (vec![line], panel)
            }
            None => (Vec::new(), None),
        };
        let settings = RenderSettings {
            overlays: Overlays {
                stress: true,
                ..Overlays::default()
            },
            stress_max: self.drawing.scale,
            background,
            background_alpha,
            lines,
            panel,
            ..RenderSettings::default()
        };
        let mut enc = dev
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("xr method frame"),
            });
        self.renderer
            .prepare(&mut enc, &self.drawing.state(), &settings);
        self.renderer.render(
            &mut enc,
            &[(views[0], &targets[0]), (views[1], &targets[1])],
            headset.eye_size(),
        );
        dev.queue.submit([enc.finish()]);
        Ok(headset.end_frame(true)?)
    }

    /// The frame's tool: the scene's script until the trigger engages the controller's.
    fn tool(&mut self, f: &HeadsetFrame) -> ToolInput {
        let c = f.controllers;
        self.hand |= c.blade_engaged() && c.right_grip.is_some();
        if let Some(ex) = &mut self.exercise {
            // An exercise's blade is the controller's from the start (the scene's scripted
            // cut must not open the tissue), held where it was while untracked.
            self.hand = true;
            if let Some(grip) = c.right_grip {
                ex.pose = scalpel_pose(grip, BladeOffset::default(), &self.tray);
            }
            return ToolInput::Hand {
                pose: ex.pose,
                engaged: c.blade_engaged() && c.right_grip.is_some(),
            };
        }
        match (self.hand, c.right_grip) {
            (true, Some(grip)) => ToolInput::Hand {
                pose: scalpel_pose(grip, BladeOffset::default(), &self.tray),
                engaged: c.blade_engaged(),
            },
            _ => ToolInput::Script,
        }
    }
}

/// A renderer for the drawing's current topology.
fn renderer_for(dev: &RenderDevice, format: wgpu::TextureFormat, d: &TetDrawing) -> Renderer {
    let r = &d.render;
    Renderer::new(&dev.device, &dev.queue, format, &r.mesh, &r.skin)
}
