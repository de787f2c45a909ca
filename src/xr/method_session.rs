//! The headset session for a scene of any method: the organ on the tray, its body stepped
//! on its own thread ([`MethodThread`], the default on a real-time headset: the display
//! draws the newest completed frame and never waits) or inside each display frame up to
//! the frame's display time (a simulated headset's virtual clock, or `--sim in-frame`),
//! with the scene's own script (the Nakao blade's stroke, the rheology indenter) until the
//! right controller's trigger takes the tool: then the scalpel cuts (Nakao) or presses
//! (rheology) where the controller holds it, vibrating with the method's tool force where
//! it has one. Both eyes show the heat map of the method's own quantity. Writes the body's
//! `report.json` (the run's schema) into the output folder.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use incise_scalpel::HapticCurve;
use incise_xr::openxr::haptics::haptic_pulse;
use incise_xr::openxr::scalpel_pose::{BladeOffset, scalpel_pose};
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{FrameEvent, Headset, HeadsetFrame, eye::eye_view};
use incise_xr::{Overlays, RenderDevice, RenderSettings, Renderer};

use super::method_thread::{MethodCommand, MethodThread};
use super::script::{HeadsetScript, RightTrack};
use super::sim_mode::{self, SimChoice, SimMode};
use super::sim_thread::MAX_CATCH_UP;
use super::simulated::SimulatedHeadset;
use crate::bench::soak::percentile;
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

/// The body of a session: stepped inside the display frame, or on its own thread.
enum Stepper {
    /// In the frame: the display waits for the steps.
    InFrame(Box<RecordedBody>, Duration),
    /// On a thread; the display draws its newest frame (`shown`: its frame count).
    Thread(MethodThread, usize),
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
    frames: u64,
    rendered: u64,
    pulses: u64,
    haptic: HapticCurve,
    /// Wall time of each display frame's work (stepping, vibration, drawing), ms.
    frame_ms: Vec<f64>,
    /// Simulated time given up by an in-frame body slower than real time, s.
    given_up: f64,
}

/// Run `scene` (any method but XPBD) on the simulated headset playing `script_path`,
/// writing eye images and `report.json` to `out`; the session's summary line.
pub fn run_simulated(
    scene: &Path,
    script_path: &Path,
    out: &Path,
    sim: &MethodSim,
) -> Result<String> {
    let script = HeadsetScript::load(script_path)?;
    let (mode, why) = sim_mode::resolve(sim.choice, false, !script.realtime)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let (stepper, drawing) = open_stepper(scene, out, mode, sim.slow)?;
    let tray = tray_for(&drawing);
    let stroke = tool_stroke(&script, script_path)?;
    let dev = RenderDevice::headless()?;
    let offset = BladeOffset::default();
    let mut headset = SimulatedHeadset::new(script, stroke, tray, offset, dev, out)?;
    run_on(
        &mut headset,
        scene,
        (stepper, drawing),
        tray,
        out,
        (mode, why),
        sim.frames,
    )
}

/// Run `scene` (any method but XPBD) on the runtime's `headset` (real time: the body on
/// its own thread unless `sim` says otherwise), writing `report.json` to `out`; the
/// session's summary line.
pub fn run_on_runtime(
    headset: &mut dyn Headset,
    scene: &Path,
    out: &Path,
    sim: &MethodSim,
) -> Result<String> {
    let (mode, why) = sim_mode::resolve(sim.choice, false, false)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let opened = open_stepper(scene, out, mode, sim.slow)?;
    let tray = tray_for(&opened.1);
    run_on(headset, scene, opened, tray, out, (mode, why), sim.frames)
}

/// Open `scene`'s body as `mode` says (slowed by `slow` a frame), writing its report to
/// `out` at the end; the body and its first drawing.
fn open_stepper(
    scene: &Path,
    out: &Path,
    mode: SimMode,
    slow: Duration,
) -> Result<(Stepper, TetDrawing)> {
    let (stepper, view) = match mode {
        SimMode::InFrame => {
            let body = RecordedBody::open(scene)?;
            let view = body.body.tet_view();
            (Stepper::InFrame(Box::new(body), slow), view)
        }
        SimMode::Thread => {
            let mut t = MethodThread::spawn(scene, out.join("report.json"), slow)?;
            let first = t.latest()?;
            (Stepper::Thread(t, first.frames), first.view.clone())
        }
    };
    let drawing = TetDrawing::new(view).with_context(|| format!("{}: drawing", scene.display()))?;
    Ok((stepper, drawing))
}

/// The tray that holds the body of `drawing`.
fn tray_for(drawing: &TetDrawing) -> Tray {
    let (lo, hi) = drawing.render.mesh.rest_bounds();
    Tray::for_bounds(lo, hi)
}

/// Run the opened body of `scene` (from [`open_stepper`]) on `headset` with the organ on
/// `tray` (ending it after `max_frames` display frames, if given); `report.json` written
/// to `out`; the session's summary line, saying where the body was stepped (`mode`, and
/// why) and what a display frame cost.
fn run_on(
    headset: &mut dyn Headset,
    scene: &Path,
    (stepper, drawing): (Stepper, TetDrawing),
    tray: Tray,
    out: &Path,
    (mode, why): (SimMode, String),
    max_frames: Option<u64>,
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
        frames: 0,
        rendered: 0,
        pulses: 0,
        haptic: HapticCurve::default(),
        frame_ms: Vec::new(),
        given_up: 0.0,
    };
    let mut exit_asked = false;
    while let Some(frame) = next(headset)? {
        let t0 = Instant::now();
        s.frame(headset, &dev, &frame)?;
        s.frame_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        if !exit_asked && max_frames.is_some_and(|m| s.frames >= m) {
            headset.request_exit()?;
            exit_asked = true;
        }
    }
    let (frames, rendered, pulses) = (s.frames, s.rendered, s.pulses);
    s.frame_ms.sort_by(f64::total_cmp);
    let (p50, p95) = (percentile(&s.frame_ms, 0.5), percentile(&s.frame_ms, 0.95));
    let summary = match s.stepper {
        Stepper::InFrame(body, _) => body.close(Some(&out.join("report.json")))?,
        Stepper::Thread(thread, _) => thread.finish()?,
    };
    Ok(format!(
        "{} on {}: {frames} display frames ({rendered} rendered), {pulses} vibration pulses, \
         body stepped {} ({why}), display frame work p50 {p50:.2} ms, p95 {p95:.2} ms; {summary}",
        scene.display(),
        headset.describe(),
        mode.name(),
    ))
}

/// The next begun frame, `None` when the session has ended.
fn next(headset: &mut dyn Headset) -> Result<Option<HeadsetFrame>> {
    loop {
        match headset.next_frame()? {
            FrameEvent::Frame(f) => return Ok(Some(*f)),
            FrameEvent::Idle => continue,
            FrameEvent::Ended(_) => return Ok(None),
        }
    }
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
    /// One display frame: step the body up to the frame's display time with the tool,
    /// vibrate, draw both eyes.
    fn frame(
        &mut self,
        headset: &mut dyn Headset,
        dev: &RenderDevice,
        f: &HeadsetFrame,
    ) -> Result<()> {
        self.frames += 1;
        let start = *self.start.get_or_insert(f.display_time);
        let tool = self.tool(f);
        let (force, changed) = self.advance(tool, f.display_time - start - self.given_up)?;
        if changed {
            self.renderer = renderer_for(dev, headset.format(), &self.drawing);
        }
        let pulse = haptic_pulse(self.haptic.amplitude(force), self.hand, f.display_period);
        if pulse.is_some() {
            self.pulses += 1;
        }
        headset.vibrate(pulse)?;
        if !f.should_render {
            return Ok(headset.end_frame(false)?);
        }
        let targets = headset.acquire()?;
        let stage_from_sim = self.tray.stage_from_sim();
        let views = f
            .eyes
            .map(|(pose, fov)| eye_view(pose, fov, stage_from_sim));
        let (background, background_alpha) = headset.backdrop().clear();
        let settings = RenderSettings {
            overlays: Overlays {
                stress: true,
                ..Overlays::default()
            },
            stress_max: self.drawing.scale,
            background,
            background_alpha,
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
        headset.end_frame(true)?;
        self.rendered += 1;
        Ok(())
    }

    /// Step the body in the frame, or hand its thread the frame's command, up to
    /// simulated time `until` with `tool`; the force on the tool, N, and whether the
    /// drawing's topology changed.
    fn advance(&mut self, tool: ToolInput, until: f64) -> Result<(f32, bool)> {
        let (view, force) = match &mut self.stepper {
            Stepper::InFrame(body, slow) => {
                let dt = body.body.frame_dt();
                let mut stepped = 0;
                while body.body.time() + 0.5 * dt < until && stepped < MAX_CATCH_UP {
                    body.step(&tool).map_err(anyhow::Error::msg)?;
                    std::thread::sleep(*slow);
                    stepped += 1;
                }
                // A body slower than real time gives the owed time up rather than hold
                // every later display frame (as the XPBD frame pacer does).
                let owed = until - body.body.time() - 0.5 * dt;
                if owed > 0.0 {
                    self.given_up += owed;
                }
                let force = body.body.tool_force().map_or(0.0, |v| v.length());
                ((stepped > 0).then(|| body.body.tet_view()), force)
            }
            Stepper::Thread(thread, shown) => {
                thread.post(MethodCommand { tool, until });
                let s = thread.latest()?;
                let fresh = s.frames != *shown;
                *shown = s.frames;
                (fresh.then(|| s.view.clone()), s.force)
            }
        };
        let changed = match view {
            Some(v) => self.drawing.update(v)?,
            None => false,
        };
        Ok((force, changed))
    }

    /// The frame's tool: the scene's script until the trigger engages the controller's.
    fn tool(&mut self, f: &HeadsetFrame) -> ToolInput {
        let c = f.controllers;
        self.hand |= c.blade_engaged() && c.right_grip.is_some();
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
