//! The headset session for a scene of any method: the organ on the tray, its body stepped
//! on its own thread ([`super::method_thread`], the default on a real-time headset: the display
//! draws the newest completed frame and never waits) or inside each display frame up to
//! the frame's display time (a simulated headset's virtual clock, or `--sim in-frame`),
//! with the scene's own script (the Nakao blade's stroke, the rheology indenter) until the
//! right controller's trigger takes the tool: then the scalpel cuts (Nakao) or presses
//! (rheology) where the controller holds it, vibrating with the method's tool force where
//! it has one. Both eyes show the heat map of the method's own quantity. The display loop
//! is XPBD's ([`super::frame_loop`]): the same controls (Menu pauses, B toggles the heat
//! map, the left grip moves the tray), the blade drawn where the controller holds it, the
//! same frame log and endings. Writes the body's
//! `report.json` (the run's schema) into the output folder, and the session's frame log
//! (`frames.csv`) and `xr_report.json` as an XPBD session does (also when it fails).

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use glam::{Quat, Vec3};
use incise_scalpel::HapticCurve;
use incise_sim::contact::ToolPose;
use incise_xr::openxr::scalpel_pose::BladeOffset;
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{Headset, HeadsetFrame};
use incise_xr::{RenderDevice, Renderer};

use super::exercise::XrExercise;
use super::frame_loop::{DisplayOptions, DisplayOutcome, drive};
use super::headset_sim::{HeadsetSim, Picture};
use super::method_stepper::Stepper;
use super::script::{HeadsetScript, RightTrack};
use super::sim_mode::{self, SimChoice, SimMode};
use super::sim_state::{Advanced, CommandStamp, ToolCommand};
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

/// A method session's body as the display loop drives it.
struct Session {
    stepper: Stepper,
    drawing: TetDrawing,
    renderer: Renderer,
    /// The headset's device and colour format (a changed topology needs a new renderer).
    dev: (RenderDevice, wgpu::TextureFormat),
    /// Whether the controller has taken the tool from the scene's script.
    hand: bool,
    /// The blade drawn: the controller's, while it holds the tool and is tracked; the
    /// scene's scripted blade while the script holds it.
    drawn_tool: Option<ToolPose>,
    /// The display time of the first frame, s (simulated time 0).
    start: Option<f64>,
    /// The display time of the previous frame, s.
    previous: Option<f64>,
    /// Simulated time held back: given up by an in-frame body slower than real time, and
    /// the time spent paused, s.
    given_up: f64,
    /// A Nakao exercise: its plan drawn, attempts recorded from the controller and
    /// scored on the body's cut surface (the body stepped in the frame).
    exercise: Option<HeadsetExercise>,
    /// What A opens afresh: the scene, the output folder its report is written to, where
    /// the body is stepped and how its frames are slowed.
    reopen: (PathBuf, PathBuf, SimMode, Duration),
}

/// A method session's exercise.
pub struct HeadsetExercise {
    /// The exercise and its attempts.
    pub live: XrExercise<RecordedBody>,
    /// The blade's last tracked pose (held, lifted, while the controller is untracked).
    pose: ToolPose,
}

impl HeadsetExercise {
    /// Open the exercise at `path`, attempts saved under `out_root` and appended to
    /// `history`.
    pub fn open(path: &Path, out_root: &Path, history: &Path) -> Result<HeadsetExercise> {
        Ok(HeadsetExercise {
            live: XrExercise::open(path, out_root, history)?,
            // Out of reach until the controller is tracked.
            pose: ToolPose {
                position: Vec3::new(0.0, 0.0, 1.0),
                rotation: Quat::IDENTITY,
            },
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
    exercise: Option<HeadsetExercise>,
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
    exercise: Option<HeadsetExercise>,
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
    (stepper, drawing, exercise): (Stepper, TetDrawing, Option<HeadsetExercise>),
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
        dev: (dev, headset.format()),
        hand: false,
        drawn_tool: None,
        start: None,
        previous: None,
        given_up: 0.0,
        exercise,
        reopen: (scene.to_path_buf(), out.to_path_buf(), mode, sim.slow),
    };
    let curve = HapticCurve::default();
    let display = DisplayOptions {
        max_frames: sim.frames,
        blade: BladeOffset::default(),
        haptic: &|f| curve.amplitude(f),
        tray,
        played: false,
    };
    let shown = drive(headset, &mut s, &display);
    let report = s.report(headset, scene, &shown, (mode, why.clone()), sim.slow)?;
    let (p50, p95) = work_p50_p95(&shown);
    let (report, summary) = s.close(shown, report, out)?;
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

/// Median and 95th percentile of the display frames' own work (stepping, vibration,
/// drawing), ms.
fn work_p50_p95(shown: &DisplayOutcome) -> (f64, f64) {
    let mut ms: Vec<f64> = shown.log.rows.iter().map(|r| r.frame_ms).collect();
    ms.sort_by(f64::total_cmp);
    (percentile(&ms, 0.5), percentile(&ms, 0.95))
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

    /// Keep body frame `b` for the attempt under way, stepped with `tool` (its pose
    /// recorded when the controller tracked it: `tracked`).
    fn keep(
        ex: &mut HeadsetExercise,
        b: &RecordedBody,
        tool: &ToolInput,
        tracked: bool,
    ) -> Result<()> {
        let (Some(frame), ToolInput::Hand { pose, engaged }) = (b.last_frame(), tool) else {
            return Ok(());
        };
        let pose = tracked.then_some(*pose);
        ex.live
            .after_step(ToolFrame::of(frame), pose, *engaged, b.body.frame_dt())
    }

    /// Close the body after the display loop (its `report.json` written unless the
    /// session failed), then write `frames.csv` and `report` (completed with the body
    /// frames stepped, their rate over the loop's wall time and how the session ended)
    /// into `out`, also on a failure; the report and the body's summary line.
    fn close(
        self,
        shown: DisplayOutcome,
        mut report: XrReport,
        out: &Path,
    ) -> Result<(XrReport, String)> {
        let closed = match shown.error {
            Some(e) => Err(e),
            None => self.stepper.close(out),
        };
        if let Ok((_, frames)) = &closed {
            report.sim_frames = *frames as u64;
        }
        if shown.wall_s > 0.0 {
            report.sim_steps_per_s = report.sim_frames as f64 / shown.wall_s;
        }
        report.exit = xr_report::exit_text(closed.as_ref().err(), shown.interrupted, shown.exit);
        report.save(&shown.log, out)?;
        let kept = "the frame log and xr_report.json";
        match closed {
            // Ctrl-C: the session ended cleanly, but the run was cut short (exit 130).
            Ok(_) if shown.interrupted => {
                Err(xr_report::interrupted(&report.scene, report.frames, out))
            }
            Ok((summary, _)) => Ok((report, summary)),
            Err(e) => Err(xr_report::failed(e, report.frames, kept, out)),
        }
    }

    /// The session's `xr_report.json` so far: `scene` on `headset` as the display loop
    /// `shown` it, stepped `mode` (why), each body frame slowed by `slow`, the frames
    /// stepped as many as published.
    fn report(
        &self,
        headset: &dyn Headset,
        scene: &Path,
        shown: &DisplayOutcome,
        (mode, why): (SimMode, String),
        slow: Duration,
    ) -> Result<XrReport> {
        let (method, solver_device) = self.stepper.body()?;
        let rows = &shown.log.rows;
        Ok(XrReport {
            scene: scene.display().to_string(),
            solver_device,
            sim_mode: mode.name().into(),
            sim_mode_why: why,
            sim_frames: self.stepper.frames() as u64,
            max_tool_force: rows.iter().map(|r| r.tool_force).fold(0.0, f32::max),
            haptic_pulses: shown.haptic_pulses,
            haptic_stops: shown.haptic_stops,
            dropped_time_s: self.given_up,
            slow_sim_ms: slow.as_millis() as u64,
            exercise: (self.exercise.as_ref())
                .map(|e| e.live.exercise().path.display().to_string()),
            attempts: self
                .exercise
                .as_ref()
                .map_or(Vec::new(), |e| e.live.attempts.clone()),
            ..XrReport::new(method, &shown.log, headset)
        })
    }

    /// The frame's tool from its command: the scene's script until the trigger engages
    /// the controller's.
    fn tool(&mut self, cmd: &ToolCommand) -> ToolInput {
        self.hand |= cmd.engaged && cmd.pose.is_some();
        if let Some(ex) = &mut self.exercise {
            // An exercise's blade is the controller's from the start (the scene's scripted
            // cut must not open the tissue), held where it was while untracked.
            self.hand = true;
            if let Some(pose) = cmd.pose {
                ex.pose = pose;
            }
            return ToolInput::Hand {
                pose: ex.pose,
                engaged: cmd.engaged && cmd.pose.is_some(),
            };
        }
        match (self.hand, cmd.pose) {
            (true, Some(pose)) => ToolInput::Hand {
                pose,
                engaged: cmd.engaged,
            },
            _ => ToolInput::Script,
        }
    }

    /// Simulated time the body is stepped to at `frame`: the display time since the
    /// first frame, less the time given up and the time paused (`paused`).
    fn until(&mut self, frame: &HeadsetFrame, paused: bool) -> f64 {
        let start = *self.start.get_or_insert(frame.display_time);
        let previous = self.previous.replace(frame.display_time);
        if paused {
            self.given_up += previous.map_or(0.0, |p| frame.display_time - p);
        }
        frame.display_time - start - self.given_up
    }

    /// A new drawing `view` of the body: a changed topology needs a new renderer (and the
    /// card uploaded to it again).
    fn redraw(&mut self, view: crate::sim_body::TetView) -> Result<()> {
        if self.drawing.update(view)? {
            self.renderer = renderer_for(&self.dev.0, self.dev.1, &self.drawing);
            if let Some(ex) = &mut self.exercise {
                ex.live.renderer_replaced();
            }
        }
        Ok(())
    }
}

impl HeadsetSim for Session {
    fn heat_map_at_start(&self) -> bool {
        // The method's own quantity (tension, strain) is what the session is for.
        true
    }

    fn start(&mut self) -> Result<()> {
        self.start_attempt()
    }

    /// A pressed: in an exercise an attempt the blade touched is finished (its card
    /// shown); otherwise the scene starts over, loaded afresh (an exercise's new attempt
    /// starts on it; outside one the scene's script holds the tool again).
    fn on_a(&mut self) -> Result<()> {
        if let (Some(ex), Stepper::InFrame { body, .. }) = (&mut self.exercise, &self.stepper)
            && !ex.live.on_a(body)?
        {
            return Ok(());
        }
        let (scene, out, mode, slow) = &self.reopen;
        (self.stepper, self.drawing) = Stepper::open(scene, out, *mode, *slow)?;
        self.renderer = renderer_for(&self.dev.0, self.dev.1, &self.drawing);
        if let Some(ex) = &mut self.exercise {
            ex.live.renderer_replaced();
        }
        self.hand = false;
        // The fresh body's time 0 is the next display frame's.
        (self.start, self.previous, self.given_up) = (None, None, 0.0);
        self.start_attempt()
    }

    /// Step the body up to the frame's display time with the frame's tool (held while
    /// paused).
    fn advance(&mut self, frame: &HeadsetFrame, cmd: &ToolCommand) -> Result<Advanced> {
        let tool = self.tool(cmd);
        let until = self.until(frame, cmd.paused);
        let stamp = (cmd.frame, frame.display_time);
        let tracked = cmd.pose.is_some();
        let ex = &mut self.exercise;
        let step = self
            .stepper
            .advance(tool, until, stamp, &mut |b| match ex {
                Some(ex) => Session::keep(ex, b, &tool, tracked),
                None => Ok(()),
            })?;
        self.given_up += step.given_up;
        // The controller's blade where it holds the tool; the scene's scripted blade
        // (where the method's tool is a scalpel) while the script holds it.
        self.drawn_tool = match tool {
            ToolInput::Hand { pose, .. } => tracked.then_some(pose),
            ToolInput::Script => step.scalpel,
        };
        if let Some(view) = step.view {
            self.redraw(view)?;
        }
        Ok(step.done)
    }

    fn vibrates(&self, _: &ToolCommand) -> bool {
        // The method's tool force is felt while the controller holds the tool.
        self.hand
    }

    fn picture(&mut self, tray: &Tray, head: Vec3) -> Result<Option<Picture<'_>>> {
        let (lines, panel) = match &mut self.exercise {
            Some(ex) => {
                let panel = ex.live.panel(&mut self.renderer, &self.dev.0, tray, head)?;
                let line = ex.live.decal().line(self.drawing.state().positions);
                (vec![line], panel)
            }
            None => (Vec::new(), None),
        };
        Ok(Some(Picture {
            renderer: &mut self.renderer,
            body: self.drawing.state(),
            heat_max: self.drawing.scale,
            tool: self.drawn_tool,
            lines,
            panel,
        }))
    }

    fn shown_command(&self) -> Option<CommandStamp> {
        self.stepper.last_command()
    }

    fn end(&mut self) -> Result<()> {
        match (&mut self.exercise, &self.stepper) {
            (Some(ex), Stepper::InFrame { body, .. }) => ex.live.end_session(body),
            _ => Ok(()),
        }
    }
}

/// A renderer for the drawing's current topology.
fn renderer_for(dev: &RenderDevice, format: wgpu::TextureFormat, d: &TetDrawing) -> Renderer {
    let r = &d.render;
    Renderer::new(&dev.device, &dev.queue, format, &r.mesh, &r.skin)
}
