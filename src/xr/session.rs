//! The headset session, one for every method: the organ on the tray, its body stepped on
//! its own thread (the default on a real-time headset: the display draws the newest
//! completed frame and never waits) or inside each display frame (a simulated headset's
//! virtual clock, an exercise, or `--sim in-frame`). The tool is the right controller's
//! (sharp while the trigger is held, pushing dulled otherwise), the scene's own script
//! until the trigger takes it where the method has one (a Nakao blade, a rheology
//! indenter), or a played stroke. The display loop ([`super::frame_loop`]) gives the
//! controls (A starts over or finishes an exercise attempt, Menu pauses, B toggles the
//! heat map, the left grip moves the tray). Writes the body's `report.json` (the run's
//! schema), and the frame log (`frames.csv`), `xr_report.json` and the scalpel's path
//! (`stroke.ron`, for `incise run --stroke`) also when the session fails.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::{Quat, Vec3};
use incise_scalpel::{HapticCurve, Stroke};
use incise_sim::contact::ToolPose;
use incise_xr::openxr::scalpel_pose::BladeOffset;
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{Headset, HeadsetFrame};
use incise_xr::{RenderDevice, Renderer, SurfaceLine};

use super::command::{Advanced, BodyCommand, CommandStamp, ToolCommand};
use super::exercise::XrExercise;
use super::frame_loop::{DisplayOptions, DisplayOutcome, drive};
use super::headset_sim::{HeadsetSim, Picture};
use super::live_sim::LiveSim;
use super::sim_mode::SimMode;
use super::stepper::{FrameHook, Stepper, SteppingEnd};
use super::xr_report::{self, XrReport};
use crate::exercise::ToolFrame;
use crate::pictures::body_drawing::BodyDrawing;
use crate::quantile::percentile;
use crate::scene::Method;
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{BodyView, ToolInput};

/// A session's exercise.
pub struct HeadsetExercise {
    /// The exercise and its attempts.
    pub live: XrExercise,
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

/// How a session runs, besides its body and headset.
pub struct SessionPlan {
    /// The scene file (named in the report).
    pub scene: PathBuf,
    /// The output folder.
    pub out: PathBuf,
    /// Where the body is stepped, and why.
    pub mode: (SimMode, String),
    /// Keep the scene's substeps whatever the cost (a played stroke, a nominal script).
    pub nominal: bool,
    /// Stop after this many display frames.
    pub frames: Option<u64>,
    /// The tray at the start.
    pub tray: Tray,
    /// The stroke played instead of the controller, and its file.
    pub played: Option<PathBuf>,
    /// Also write the recorded stroke here.
    pub record_stroke: Option<PathBuf>,
    /// The testing aid's slowdown a body frame, ms (in the report).
    pub slow_ms: u64,
    /// The exercise.
    pub exercise: Option<HeadsetExercise>,
    /// The exercise's file.
    pub exercise_file: Option<PathBuf>,
}

/// A session's body as the display loop drives it.
struct Session {
    stepper: Stepper,
    drawing: BodyDrawing,
    renderer: Renderer,
    /// The headset's device and colour format (a changed topology needs a new renderer).
    dev: (RenderDevice, wgpu::TextureFormat),
    method: Method,
    /// Whether the body's script moves its tool until the trigger takes it.
    script_holds: bool,
    /// Whether a played stroke drives the tool.
    played: bool,
    /// Whether the controller has taken the tool.
    hand: bool,
    /// The blade drawn.
    drawn_tool: Option<ToolPose>,
    /// A presses that started the scene over.
    resets: u64,
    exercise: Option<HeadsetExercise>,
    /// The frame length, s (an exercise's clock).
    dt: f64,
}

/// An exercise's view of the frames a body stepped in the frame.
struct ExerciseHook<'a> {
    exercise: Option<&'a mut HeadsetExercise>,
    dt: f64,
}

impl FrameHook for ExerciseHook<'_> {
    fn after_step(&mut self, body: &RecordedBody, cmd: &BodyCommand) -> Result<()> {
        let (Some(ex), Some(frame), ToolInput::Hand { pose, engaged }) =
            (self.exercise.as_deref_mut(), body.last_frame(), cmd.tool)
        else {
            return Ok(());
        };
        let pose = cmd.tracked.then_some(pose);
        ex.live
            .after_step(ToolFrame::of(frame), pose, engaged, self.dt)
    }

    fn on_failure(&mut self, body: &RecordedBody, why: &str) -> Result<()> {
        match self.exercise.as_deref_mut() {
            // An attempt the blade touched is scored and saved as it stood.
            Some(ex) => ex.live.on_solver_failure(body, why),
            None => Ok(()),
        }
    }

    fn after_reset(&mut self, body: &mut RecordedBody) -> Result<()> {
        match self.exercise.as_deref_mut() {
            Some(ex) => ex.live.start(body),
            None => Ok(()),
        }
    }
}

/// Run `live` on `headset` as `plan` says, drawing `first` (its frame now) until it
/// steps; the session's summary line.
pub fn run(
    headset: &mut dyn Headset,
    (live, first): (LiveSim, BodyView),
    mut plan: SessionPlan,
) -> Result<String> {
    let dev = headset.device().clone();
    let drawing =
        BodyDrawing::new(first).with_context(|| format!("{}: drawing", plan.scene.display()))?;
    let renderer = renderer_for(&dev, headset.format(), &drawing);
    let method = live.body.body.method();
    let script_holds = live.body.body.script_holds_tool();
    let dt = live.dt();
    let stepper = match plan.mode.0 {
        SimMode::InFrame => Stepper::in_frame(live, plan.nominal),
        SimMode::Thread if plan.exercise.is_some() => {
            bail!("exercise sessions step the body in the frame loop (--sim in-frame)")
        }
        SimMode::Thread => Stepper::thread(live, plan.nominal)?,
    };
    let mut s = Session {
        stepper,
        drawing,
        renderer,
        dev: (dev, headset.format()),
        method,
        script_holds,
        played: plan.played.is_some(),
        hand: false,
        drawn_tool: None,
        resets: 0,
        exercise: plan.exercise.take(),
        dt,
    };
    let curve = HapticCurve::default();
    let display = DisplayOptions {
        max_frames: plan.frames,
        blade: BladeOffset::default(),
        haptic: &|f| curve.amplitude(f),
        tray: plan.tray,
        played: plan.played.is_some(),
    };
    eprintln!("xr: {}", headset.describe());
    eprintln!("xr: simulation {} ({})", plan.mode.0.name(), plan.mode.1);
    let shown = drive(headset, &mut s, &display);
    let attempts = (s.exercise.as_ref()).map_or(Vec::new(), |e| e.live.attempts.clone());
    let end = s.stepper.finish();
    conclude(headset, (s.method, end), shown, &plan, attempts)
}

/// After the display loop: the stroke, `report.json` (unless the session failed),
/// `frames.csv` and `xr_report.json` written to the output folder; the summary line, or
/// the session's failure (naming what was kept).
fn conclude(
    headset: &dyn Headset,
    (method, end): (Method, Result<SteppingEnd>),
    mut shown: DisplayOutcome,
    plan: &SessionPlan,
    attempts: Vec<super::exercise::AttemptSummary>,
) -> Result<String> {
    let out = &plan.out;
    let mut end = match end {
        Ok(end) => end,
        Err(e) => {
            let report = XrReport::new(method, &shown.log, headset);
            report.save(&shown.log, out)?;
            return Err(xr_report::failed(e, shown.frames, "the frame log", out));
        }
    };
    // The thread's own failure comes first: the display only saw it stop.
    if let Some(e) = end.error.take() {
        shown.error = Some(e);
    }
    let stroke = match end.live.recorded() {
        Ok(s) => s,
        Err(e) => {
            shown.error.get_or_insert(e);
            None
        }
    };
    let stroke_path = save_stroke(stroke.as_ref(), plan)?;
    let mut report = session_report(headset, &end, &shown, plan, stroke_path, attempts);
    let (p50, p95) = work_p50_p95(&shown);
    let closed = match shown.error.take() {
        Some(e) => Err(e),
        None => end.live.close(&out.join("report.json")),
    };
    report.exit = xr_report::exit_text(closed.as_ref().err(), shown.interrupted, shown.exit);
    report.save(&shown.log, out)?;
    match closed {
        // Ctrl-C: the session ended cleanly, but the run was cut short (exit 130).
        Ok(_) if shown.interrupted => Err(xr_report::interrupted(&report.scene, shown.frames, out)),
        Ok(body) => Ok(format!(
            "{} on {}: {} display frames ({} rendered), {} vibration pulses, body stepped {} \
             ({}), display frame work p50 {p50:.2} ms, p95 {p95:.2} ms; {}; {body}",
            report.scene,
            report.headset,
            report.frames,
            report.rendered,
            report.haptic_pulses,
            plan.mode.0.name(),
            plan.mode.1,
            report.summary(),
        )),
        Err(e) => Err(xr_report::failed(
            e,
            shown.frames,
            "the frame log, the stroke and xr_report.json",
            out,
        )),
    }
}

/// Write the recorded `stroke` as `stroke.ron` in the output folder (and where
/// `--record-stroke` asks); its path.
fn save_stroke(stroke: Option<&Stroke>, plan: &SessionPlan) -> Result<Option<String>> {
    let Some(stroke) = stroke else {
        return Ok(None);
    };
    let p = plan.out.join("stroke.ron");
    stroke.save(&p)?;
    if let Some(extra) = &plan.record_stroke {
        stroke.save(extra)?;
    }
    Ok(Some(p.display().to_string()))
}

/// The session's `xr_report.json` (its `exit` filled in by the caller).
fn session_report(
    headset: &dyn Headset,
    end: &SteppingEnd,
    shown: &DisplayOutcome,
    plan: &SessionPlan,
    stroke: Option<String>,
    attempts: Vec<super::exercise::AttemptSummary>,
) -> XrReport {
    let live = &end.live;
    let body = &live.body.body;
    let cut = live.cut();
    let wall = end.wall_s.unwrap_or(shown.wall_s);
    XrReport {
        scene: plan.scene.display().to_string(),
        solver_device: body.device(),
        sim_mode: plan.mode.0.name().into(),
        sim_mode_why: plan.mode.1.clone(),
        sim_frames: live.frames,
        released_tets: cut.map(|c| c.0),
        cut_box: cut.and_then(|c| c.1),
        max_tool_force: live.max_force,
        haptic_pulses: shown.haptic_pulses,
        haptic_stops: shown.haptic_stops,
        drawn: shown.drawn,
        dropped_time_s: end.dropped_time,
        sim_steps_per_s: if wall > 0.0 {
            live.frames as f64 / wall
        } else {
            0.0
        },
        slow_sim_ms: plan.slow_ms,
        substeps: body.substeps().map(|s| (s.nominal, live.min_substeps)),
        solver_resets: Some(live.failures),
        stroke,
        played_stroke: plan.played.as_ref().map(|p| p.display().to_string()),
        exercise: plan.exercise_path(),
        attempts,
        ..XrReport::new(body.method(), &shown.log, headset)
    }
}

/// Median and 95th percentile of the display frames' own work (stepping, vibration,
/// drawing), ms.
fn work_p50_p95(shown: &DisplayOutcome) -> (f64, f64) {
    let mut ms: Vec<f64> = shown.log.rows.iter().map(|r| r.frame_ms).collect();
    ms.sort_by(f64::total_cmp);
    (percentile(&ms, 0.5), percentile(&ms, 0.95))
}

impl Session {
    /// The frame's tool from its command: a played stroke's; an exercise's controller,
    /// held where it was while untracked; else the controller's once it has taken the
    /// tool (at once where the body has no script moving it, else when the trigger
    /// engages), the body's script until then and while untracked.
    fn tool(&mut self, cmd: &ToolCommand) -> ToolInput {
        if self.played {
            return ToolInput::Script;
        }
        if let Some(ex) = &mut self.exercise {
            // An exercise's blade is the controller's from the start (the scene's scripted
            // cut must not open the tissue).
            self.hand = true;
            if let Some(pose) = cmd.pose {
                ex.pose = pose;
            }
            return ToolInput::Hand {
                pose: ex.pose,
                engaged: cmd.engaged && cmd.pose.is_some(),
            };
        }
        self.hand |= cmd.pose.is_some() && (cmd.engaged || !self.script_holds);
        match (self.hand, cmd.pose) {
            (true, Some(pose)) => ToolInput::Hand {
                pose,
                engaged: cmd.engaged,
            },
            _ => ToolInput::Script,
        }
    }

    /// Draw `view` from now on: a changed topology or a new body needs a new renderer
    /// (and the card uploaded to it again).
    fn redraw(&mut self, view: BodyView) -> Result<()> {
        if self.drawing.update(view)? {
            self.renderer = renderer_for(&self.dev.0, self.dev.1, &self.drawing);
            if let Some(ex) = &mut self.exercise {
                ex.live.renderer_replaced();
            }
        }
        Ok(())
    }

    /// The exercise's plan on the tissue as drawn now (where not cut away).
    fn plan_lines(&self) -> Vec<SurfaceLine> {
        let Some(ex) = &self.exercise else {
            return Vec::new();
        };
        let decal = ex.live.decal();
        vec![match &self.drawing {
            BodyDrawing::Cut(c) => decal.line_uncut(&c.positions, c.cut.live()),
            BodyDrawing::Tets(_) => decal.line(self.drawing.state().positions),
        }]
    }
}

impl HeadsetSim for Session {
    fn heat_map_at_start(&self) -> bool {
        self.method.heat_map_first()
    }

    fn start(&mut self) -> Result<()> {
        match (&mut self.exercise, self.stepper.body()) {
            (Some(ex), Some(body)) => ex.live.start(body),
            (Some(_), None) => {
                bail!("exercise sessions step the body in the frame loop (--sim in-frame)")
            }
            (None, _) => Ok(()),
        }
    }

    /// A pressed: in an exercise an attempt the blade touched is finished (its card
    /// shown); otherwise the scene starts over (an exercise's new attempt starts on it;
    /// outside one the scene's script holds the tool again).
    fn on_a(&mut self) -> Result<()> {
        if let (Some(ex), Some(body)) = (&mut self.exercise, self.stepper.body())
            && !ex.live.on_a(body)?
        {
            return Ok(());
        }
        self.hand = false;
        self.resets += 1;
        let mut hook = ExerciseHook {
            exercise: self.exercise.as_mut(),
            dt: self.dt,
        };
        if let Some(view) = self.stepper.reset(&mut hook)? {
            self.redraw(view)?;
        }
        Ok(())
    }

    fn after_frame(&mut self) {
        self.stepper.after_frame();
    }

    /// Step the body (or hand its thread the command) with the frame's tool.
    fn advance(&mut self, frame: &HeadsetFrame, cmd: &ToolCommand) -> Result<Advanced> {
        let tool = self.tool(cmd);
        let body_cmd = BodyCommand {
            tool,
            tracked: cmd.pose.is_some(),
            paused: cmd.paused,
            resets: self.resets,
            stamp: (cmd.frame, frame.display_time),
        };
        let mut hook = ExerciseHook {
            exercise: self.exercise.as_mut(),
            dt: self.dt,
        };
        let previous = self.drawing.cut_view();
        let step = self.stepper.advance(frame, body_cmd, &mut hook, previous)?;
        // The controller's blade where it holds the tool (and is tracked); the scene's
        // scripted blade (where the method's tool is a scalpel) while the script holds it.
        self.drawn_tool = match tool {
            ToolInput::Hand { pose, .. } => cmd.pose.is_some().then_some(pose),
            ToolInput::Script if self.script_holds => step.scalpel,
            ToolInput::Script => None,
        };
        if let Some(view) = step.view {
            self.redraw(view)?;
        }
        Ok(step.done)
    }

    fn vibrates(&self, cmd: &ToolCommand) -> bool {
        // The tool force is felt while the controller holds the tool: once the trigger took
        // it from the body's script, else while the trigger is held (or a stroke plays).
        match self.script_holds && !self.played {
            true => self.hand,
            false => cmd.engaged,
        }
    }

    fn picture(&mut self, tray: &Tray, head: Vec3) -> Result<Option<Picture<'_>>> {
        let lines = self.plan_lines();
        let panel = match &mut self.exercise {
            Some(ex) => ex.live.panel(&mut self.renderer, &self.dev.0, tray, head)?,
            None => None,
        };
        Ok(Some(Picture {
            renderer: &mut self.renderer,
            body: self.drawing.state(),
            heat_max: self.drawing.scale(),
            tool: self.drawn_tool,
            lines,
            panel,
        }))
    }

    fn shown_command(&self) -> Option<CommandStamp> {
        self.stepper.last_command()
    }

    fn stroke_done(&self) -> bool {
        self.stepper.stroke_done()
    }

    fn end(&mut self) -> Result<()> {
        match (&mut self.exercise, self.stepper.body()) {
            (Some(ex), Some(body)) => ex.live.end_session(body),
            _ => Ok(()),
        }
    }
}

impl SessionPlan {
    /// The exercise's file, for the report.
    fn exercise_path(&self) -> Option<String> {
        self.exercise_file.as_ref().map(|p| p.display().to_string())
    }
}

/// A renderer for the drawing's current mesh.
fn renderer_for(dev: &RenderDevice, format: wgpu::TextureFormat, d: &BodyDrawing) -> Renderer {
    let (mesh, skin) = d.mesh_and_skin();
    Renderer::new(&dev.device, &dev.queue, format, mesh, skin)
}
