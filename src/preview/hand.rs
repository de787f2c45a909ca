//! The mouse's hand on the tool, for a body of any method: the scene's script moves the
//! tool (an XPBD stroke, a Nakao blade, a rheology indenter) until the left button takes
//! it, or from the start where the scene has no script or an exercise gives the blade to
//! the mouse. Each frame the hand says where the tool goes ([`ToolInput`]): the mouse
//! blade advanced ([`ScalpelInput`]), or a played stroke (an exercise's reference),
//! engaged while the button is down. While recording, that pose is stored and handed to
//! the body as stored, so `incise run --stroke` and `incise exercise --stroke` replay
//! the same bits. No window needed: tests drive it with synthetic events.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use glam::Vec3;
use incise_scalpel::{HapticCurve, Stroke, StrokeRecorder, Tool};
use incise_sim::contact::ToolPose;

use super::scalpel_input::{BladeGeometry, ScalpelFeel, ScalpelInput};
use crate::exercise::StrokeSource;
use crate::sim_body::ToolInput;
use crate::sim_body::recorded::RecordedBody;

/// A finished recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Recorded {
    /// Poses written (one per simulated frame, plus the start).
    pub poses: usize,
    /// Frames to give `incise run --frames` to replay all of it.
    pub frames: u64,
}

/// Who moves the tool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Holder {
    /// The body's own script.
    Script,
    /// The mouse blade.
    Mouse,
    /// The played stroke.
    Stroke,
}

/// The preview's hand.
pub struct PreviewHand {
    /// The tool drawn for the mouse (the scene's scalpel, else the built-in No. 10).
    pub tool: Tool,
    /// The mouse's blade.
    pub input: ScalpelInput,
    holder: Holder,
    played: Option<Stroke>,
    recorder: Option<StrokeRecorder>,
    haptic: HapticCurve,
    /// Magnitude of the tissue's force on the tool in the last frame, N.
    pub force: f32,
    /// Vibration amplitude for that force, 0..1.
    pub amplitude: f32,
}

impl PreviewHand {
    /// A hand for `body` holding `tool`, its blade parked high over the top centre of the
    /// tissue's rest bounds `(lo, hi)` until the cursor brings it down, its flat turned
    /// toward a camera at `yaw`. The body's script keeps the tool until the mouse takes
    /// it, where the body has one.
    pub fn new(tool: Tool, body: &RecordedBody, (lo, hi): (Vec3, Vec3), yaw: f32) -> PreviewHand {
        let top = Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), hi.z);
        let mut input = ScalpelInput::new(
            BladeGeometry::of(&tool),
            ScalpelFeel::default(),
            top,
            yaw + std::f32::consts::FRAC_PI_2,
        );
        // Parked one bounding-box diagonal up: clear of tissue that grabs lift.
        input.park((hi - lo).length());
        let mut hand = PreviewHand {
            tool,
            input,
            holder: Holder::Script,
            played: None,
            recorder: None,
            haptic: HapticCurve::default(),
            force: 0.0,
            amplitude: 0.0,
        };
        hand.fit(body);
        hand
    }

    /// Who moves the tool now.
    pub fn holder(&self) -> Holder {
        self.holder
    }

    /// A new `body` (a scene loaded or reset): its script has the tool back where it has
    /// one, else the mouse keeps it; a played stroke stops.
    pub fn fit(&mut self, body: &RecordedBody) {
        self.played = None;
        self.holder = match body.body.script_holds_tool() {
            true => Holder::Script,
            false => Holder::Mouse,
        };
    }

    /// Let the mouse move the tool from where the body's script (or the played stroke)
    /// has it now.
    pub fn take_mouse(&mut self, body: &RecordedBody) {
        if self.holder != Holder::Mouse {
            // A scalpel continues from where the script has it; another tool (an
            // indenter), or a blade not yet drawn, gives way to the mouse's blade
            // hovering over the tissue.
            match body.body.scalpel_pose() {
                Some(p) => self.input.take_over(p),
                None => self.input.park(0.0),
            }
            self.holder = Holder::Mouse;
            self.played = None;
        }
    }

    /// Let the body's script move the tool again (where it has one).
    pub fn give_back(&mut self, body: &RecordedBody) {
        if body.body.script_holds_tool() {
            self.holder = Holder::Script;
        }
    }

    /// Let `stroke` move the tool from frame 0 on (an exercise's reference stroke).
    pub fn play(&mut self, stroke: Stroke) {
        self.played = Some(stroke);
        self.holder = Holder::Stroke;
    }

    /// Whether a recording is running, and its poses so far.
    pub fn recording(&self) -> Option<usize> {
        self.recorder.as_ref().map(StrokeRecorder::len)
    }

    /// Start recording on `body`, which must be at frame 0 (a scene as loaded): the hand
    /// takes the tool, the pose now is the stroke's first key at t = 0, and the tool is put
    /// there.
    pub fn start_recording(&mut self, body: &mut RecordedBody) -> Result<()> {
        if body.frames() != 0 {
            bail!("a recording starts from the scene as loaded (frame 0)");
        }
        if self.holder == Holder::Script {
            self.take_mouse(body);
        }
        let (pose, engaged) = self.pose_at(0.0);
        let mut r = StrokeRecorder::new();
        r.push_engaged(0.0, pose, engaged)?;
        let first = r.last().ok_or_else(|| anyhow!("empty recording"))?;
        body.body.hold_tool(first.pose(), engaged)?;
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

    /// Drop a running recording without saving it; whether one was running.
    pub fn abort_recording(&mut self) -> bool {
        self.recorder.take().is_some()
    }

    /// Where the hand has the tool at time `t` since the body's start, and whether it is
    /// engaged: the played stroke's, else the mouse blade's (not advanced).
    fn pose_at(&self, t: f64) -> (ToolPose, bool) {
        match (&self.played, self.holder) {
            (Some(s), Holder::Stroke) => (s.pose_at(t), !s.lifted_at(t)),
            _ => (self.input.pose(), self.input.cutting()),
        }
    }

    /// What moves the tool in `body`'s next frame: the script, or the hand's pose at the
    /// frame's end (recorded at that time when recording, and handed over as recorded).
    pub fn tool_input(&mut self, body: &RecordedBody) -> Result<ToolInput> {
        let dt = body.body.frame_dt();
        let t = (body.frames() + 1) as f64 * dt;
        let (mut pose, engaged) = match self.holder {
            Holder::Script => return Ok(ToolInput::Script),
            Holder::Stroke => self.pose_at(t),
            Holder::Mouse => (self.input.advance(dt as f32), self.input.cutting()),
        };
        if let Some(r) = &mut self.recorder {
            r.push_engaged(t, pose, engaged)?;
            pose = r.last().map_or(pose, |k| k.pose());
        }
        Ok(ToolInput::Hand { pose, engaged })
    }

    /// After a frame of `body`: the force readout and its haptic amplitude.
    pub fn after_step(&mut self, body: &RecordedBody) {
        self.force = body.body.tool_force().map_or(0.0, |f| f.length());
        self.amplitude = self.haptic.amplitude(self.force);
    }
}

impl StrokeSource<RecordedBody> for PreviewHand {
    fn start_recording(&mut self, body: &mut RecordedBody) -> Result<()> {
        PreviewHand::start_recording(self, body)
    }

    fn is_recording(&self) -> bool {
        self.recording().is_some()
    }

    fn save_recording(&mut self, path: &Path) -> Result<()> {
        self.stop_recording(path).map(|_| ())
    }

    fn abort_recording(&mut self) {
        PreviewHand::abort_recording(self);
    }
}
