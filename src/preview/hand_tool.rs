//! The scalpel in the preview: the scene's tool (or the built-in No. 10) moved by the
//! mouse through [`ScalpelInput`] or by the scene's own stroke, its contact force and
//! haptic amplitude, and stroke recording. One call before and one after each simulated
//! frame, as `incise run` moves its tool, so a recording replays there bit for bit. No
//! window needed: tests drive it with synthetic events.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use glam::Vec3;
use incise_scalpel::{HapticCurve, Stroke, StrokeRecorder, Tool};
use incise_sim::contact::{ContactTool, ToolPose};
use incise_sim::xpbd::FrameStats;

use super::scalpel_input::{BladeGeometry, ScalpelFeel, ScalpelInput};
use crate::scene::SceneTool;
use crate::sim_body::Body;

/// A finished recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Recorded {
    /// Poses written (one per simulated frame, plus the start).
    pub poses: usize,
    /// Frames to give `incise run --frames` to replay all of it.
    pub frames: u64,
}

/// The preview's scalpel.
pub struct HandTool {
    /// The tool model (render mesh, blade shape).
    pub tool: Tool,
    contact: ContactTool,
    /// The mouse's blade.
    pub input: ScalpelInput,
    stroke: Option<Stroke>,
    /// Whether the scene's stroke moves the tool (instead of the mouse).
    pub play_stroke: bool,
    recorder: Option<StrokeRecorder>,
    haptic: HapticCurve,
    /// Magnitude of the tissue's force on the tool in the last frame, N.
    pub force: f32,
    /// Vibration amplitude for that force, 0..1.
    pub amplitude: f32,
}

impl HandTool {
    /// The scene's tool, parked high over the top centre of the tissue's rest bounds
    /// `(lo, hi)` until the cursor brings it down, its flat turned toward a camera at
    /// `yaw`. A scene's stroke is played
    /// until the mouse takes the blade.
    pub fn new(t: SceneTool, (lo, hi): (Vec3, Vec3), yaw: f32) -> HandTool {
        let top = Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), hi.z);
        let mut input = ScalpelInput::new(
            BladeGeometry::of(&t.tool),
            ScalpelFeel::default(),
            top,
            yaw + std::f32::consts::FRAC_PI_2,
        );
        // Parked one bounding-box diagonal up: clear of tissue that grabs lift.
        input.park((hi - lo).length());
        HandTool {
            play_stroke: t.stroke.is_some(),
            tool: t.tool,
            contact: t.contact,
            input,
            stroke: t.stroke,
            recorder: None,
            haptic: HapticCurve::default(),
            force: 0.0,
            amplitude: 0.0,
        }
    }

    /// Take the tool out of a scene built with `ToolDriver::Hand` and attach it to the
    /// scene's solver where it starts (the stroke's first pose, or hovering over the
    /// tissue for a camera at `yaw`).
    pub fn for_scene(built: &mut crate::scene::BuiltScene, yaw: f32) -> Result<HandTool> {
        let tool = built
            .tool
            .take()
            .ok_or_else(|| anyhow!("a hand-driven scene always has a tool"))?;
        let hand = HandTool::new(tool, built.solver.mesh().rest_bounds(), yaw);
        let dt = built.solver.params().frame_dt as f64;
        let (contact, pose) = hand.attachment(0, dt);
        built.solver.set_tool(contact, pose)?;
        Ok(hand)
    }

    /// Whether the scene has a stroke of its own.
    pub fn has_stroke(&self) -> bool {
        self.stroke.is_some()
    }

    /// The contact tool and where it is now (to attach to a new solver).
    pub fn attachment(&self, frame: u64, dt: f64) -> (ContactTool, ToolPose) {
        (self.contact.clone(), self.pose_now(frame, dt))
    }

    fn pose_now(&self, frame: u64, dt: f64) -> ToolPose {
        match (&self.stroke, self.play_stroke) {
            (Some(s), true) => s.pose_at(frame as f64 * dt),
            _ => self.input.pose(),
        }
    }

    /// Let `stroke` move the tool from frame 0 on, instead of the scene's (e.g. an
    /// exercise's reference stroke), until the mouse takes the blade.
    pub fn play(&mut self, stroke: Stroke) {
        self.stroke = Some(stroke);
        self.play_stroke = true;
    }

    /// Let the mouse move the blade from where the scene's stroke has it at `frame`.
    pub fn take_mouse(&mut self, frame: u64, dt: f64) {
        if self.play_stroke {
            let p = self.pose_now(frame, dt);
            self.input.take_over(p);
            self.play_stroke = false;
        }
    }

    /// Drop a running recording without saving it; returns whether one was running.
    pub fn abort_recording(&mut self) -> bool {
        self.recorder.take().is_some()
    }

    /// Whether a recording is running.
    pub fn recording(&self) -> Option<usize> {
        self.recorder.as_ref().map(StrokeRecorder::len)
    }

    /// Start recording on `body`, which must be at frame 0 (a scene as loaded): the pose
    /// now is the stroke's first key at t = 0 and the tool is attached there.
    pub fn start_recording(&mut self, body: &mut Body) -> Result<()> {
        if body.solver().frame() != 0 {
            bail!("a recording starts from the scene as loaded (frame 0)");
        }
        let dt = body.solver().params().frame_dt as f64;
        let mut r = StrokeRecorder::new();
        r.push(0.0, self.pose_now(0, dt))?;
        let first = r.last().ok_or_else(|| anyhow!("empty recording"))?;
        body.set_tool(self.contact.clone(), first.pose())?;
        self.recorder = Some(r);
        Ok(())
    }

    /// Stop recording and write the stroke to `path` atomically.
    pub fn stop_recording(&mut self, path: &Path) -> Result<Recorded> {
        let r = self
            .recorder
            .take()
            .ok_or_else(|| anyhow!("not recording"))?;
        let poses = r.len();
        let stroke = r
            .finish()
            .context("record at least one simulated frame before stopping")?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        stroke.save(path)?;
        Ok(Recorded {
            poses,
            frames: poses as u64 - 1,
        })
    }

    /// Before stepping `body` one frame: where the tool goes by the frame's end (the
    /// scene's stroke at `(frame + 1)·dt`, or the mouse blade advanced by `dt`), recorded
    /// at that time when recording, and handed to the solver as recorded.
    pub fn before_step(&mut self, body: &mut Body) -> Result<ToolPose> {
        let dt = body.solver().params().frame_dt as f64;
        let t = (body.solver().frame() + 1) as f64 * dt;
        let mut pose = match (&self.stroke, self.play_stroke) {
            (Some(s), true) => s.pose_at(t),
            _ => self.input.advance(dt as f32),
        };
        if let Some(r) = &mut self.recorder {
            r.push(t, pose)?;
            pose = r.last().map_or(pose, |k| k.pose());
        }
        body.move_tool(pose);
        Ok(pose)
    }

    /// After a frame: the force readout and its haptic amplitude.
    pub fn after_step(&mut self, stats: &FrameStats) {
        self.force = stats.tool_force.length();
        self.amplitude = self.haptic.amplitude(self.force);
    }
}

impl crate::exercise::StrokeSource for HandTool {
    fn start_recording(&mut self, body: &mut Body) -> Result<()> {
        HandTool::start_recording(self, body)
    }

    fn is_recording(&self) -> bool {
        self.recording().is_some()
    }

    fn save_recording(&mut self, path: &Path) -> Result<()> {
        self.stop_recording(path).map(|_| ())
    }

    fn abort_recording(&mut self) {
        HandTool::abort_recording(self);
    }
}
