//! The simulated headset's script (RON): display rate, eye size and field of view, and
//! timed head, controller and button tracks — the shape of bevy's scripted test runs,
//! with poses instead of events.

use std::path::Path;

use glam::{Quat, Vec2, Vec3};
use incise_scalpel::ToolStroke;
use serde::Deserialize;

use super::error::ScriptError;
use crate::openxr::pose::{Fov, XrPose};

/// Quest 3 display rate used unless the script says otherwise, Hz.
pub const QUEST3_HZ: f64 = 72.0;
/// Quest 3 recommended eye size over Link, pixels.
pub const QUEST3_EYE: (u32, u32) = (2064, 2208);

/// A whole script.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeadsetScript {
    /// Display rate, Hz.
    #[serde(default = "default_hz")]
    pub display_hz: f64,
    /// Eye image size, pixels (default: Quest 3's 2064×2208).
    #[serde(default = "default_eye")]
    pub eye_size: (u32, u32),
    /// Distance between the eyes, m.
    #[serde(default = "default_ipd")]
    pub ipd: f32,
    /// Left eye's field of view, radians (the right eye mirrors it).
    #[serde(default = "default_fov")]
    pub fov: FovSpec,
    /// Length of the run, s (then the session stops and exits).
    pub duration: f64,
    /// Render every K-th display frame; the others are begun and ended with no layers,
    /// as a runtime's `shouldRender = false` frames (software rendering at Quest 3 size
    /// takes about a second a frame).
    #[serde(default = "default_every")]
    pub render_every: u64,
    /// Display frames whose two eye images are saved as PNGs.
    #[serde(default)]
    pub screenshots: Vec<u64>,
    /// Draw the eye images (the default). Off: each frame to be drawn still takes the
    /// simulation's picture and uploads it, but its drawing is never submitted, as if a
    /// GPU that costs these cores nothing drew it (lavapipe draws on the cores the solver
    /// runs on): what the simulation alone adds to the latency.
    #[serde(default = "default_draw")]
    pub draw_eyes: bool,
    /// Show the room through passthrough (the eye images are transparent around the
    /// organ) instead of the opaque neutral room.
    #[serde(default)]
    pub passthrough: bool,
    /// How substeps are paced.
    #[serde(default)]
    pub pacing: Pacing,
    /// Run on the wall clock, as a runtime's frame loop does: each frame waits until its
    /// display period begins, and a frame that comes late skips the refreshes it missed
    /// (their display times are never shown). Off: a virtual clock, one period per frame
    /// however long a frame takes (deterministic, faster or slower than real time).
    #[serde(default)]
    pub realtime: bool,
    /// Head poses in stage space (+y up, −z forward), m.
    pub head: Vec<StageKey>,
    /// The right controller (the scalpel); untracked outside its keys.
    #[serde(default)]
    pub right: Option<RightTrack>,
    /// Right trigger value over time (linear between keys; 0 without keys).
    #[serde(default)]
    pub trigger: Vec<(f64, f32)>,
    /// Left grip poses in stage space; untracked outside its keys.
    #[serde(default)]
    pub left: Vec<StageKey>,
    /// Left squeeze over time.
    #[serde(default)]
    pub squeeze: Vec<(f64, f32)>,
    /// Left thumbstick over time.
    #[serde(default)]
    pub stick: Vec<(f64, Vec2)>,
    /// Button presses (held for one display frame).
    #[serde(default)]
    pub buttons: Vec<(f64, Button)>,
    /// Runtime faults injected at these times (issue 11: the session must end cleanly
    /// and keep its outputs).
    #[serde(default)]
    pub faults: Vec<(f64, XrFault)>,
}

/// A runtime fault the simulated headset can inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum XrFault {
    /// The runtime reports LOSS_PENDING (headset unplugged, Link stopped).
    SessionLoss,
    /// From the next frame's swapchain acquisition on, every call fails with
    /// `XR_ERROR_SESSION_LOST` before any event says so (the cable pulled mid-frame).
    LostCall,
    /// The runtime reports `XrEventDataInstanceLossPending` (it is going away).
    InstanceLoss,
    /// The runtime ends the session on its own: STOPPING → IDLE → EXITING (the user
    /// quit from the system menu).
    RuntimeExit,
    /// From the next frame's swapchain acquisition on, calls fail with
    /// `XR_ERROR_RUNTIME_FAILURE`: a failure that is not a clean end.
    RuntimeFailure,
}

fn default_hz() -> f64 {
    QUEST3_HZ
}
fn default_eye() -> (u32, u32) {
    QUEST3_EYE
}
fn default_ipd() -> f32 {
    0.063
}
fn default_every() -> u64 {
    1
}
fn default_draw() -> bool {
    true
}
fn default_fov() -> FovSpec {
    // Of the order a Quest 3 runtime reports for the left eye (wider towards the nose
    // side's opposite); not measured on a headset.
    FovSpec {
        left: -0.87,
        right: 0.75,
        up: 0.82,
        down: -0.87,
    }
}

/// A field of view in the script, radians.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FovSpec {
    /// Left side (negative).
    pub left: f32,
    /// Right side.
    pub right: f32,
    /// Top.
    pub up: f32,
    /// Bottom (negative).
    pub down: f32,
}

/// How the simulated run paces the simulation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
pub enum Pacing {
    /// As on a headset: substeps cut when the measured simulation time overruns the
    /// budget of a display period.
    #[default]
    Measured,
    /// Always the scene's substeps (a replay independent of this machine's speed).
    Nominal,
}

/// A timed pose in stage space.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageKey {
    /// Time, s.
    pub t: f64,
    /// Position, m.
    pub position: Vec3,
    /// Orientation (x, y, z, w); default identity (looking down −z).
    #[serde(default)]
    pub orientation: Quat,
}

/// How the right controller moves.
#[derive(Debug, Clone, Deserialize)]
pub enum RightTrack {
    /// Grip poses in stage space.
    Grip(Vec<StageKey>),
    /// The scalpel's own path in the simulation world (a stroke file or a scripted
    /// incision, as in scenes), starting at `start` s; the grip follows it through the
    /// tray and the blade offset.
    Tool {
        /// When the stroke starts, s (the controller is untracked before).
        start: f64,
        /// The stroke.
        stroke: ToolStroke,
    },
}

/// A controller button.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum Button {
    /// A: reset.
    A,
    /// B: stress overlay.
    B,
    /// Menu: pause.
    Menu,
}

impl HeadsetScript {
    /// Read and check a script file.
    pub fn load(path: &Path) -> Result<Self, ScriptError> {
        Self::parse(&incise_sim::ron_file::read(path)?, path)
    }

    /// Parse and check a script's text (`path` names it in errors).
    pub fn parse(text: &str, path: &Path) -> Result<Self, ScriptError> {
        let s: HeadsetScript = incise_sim::ron_file::parse(text, path)?;
        s.validate(path)?;
        Ok(s)
    }

    /// Ok, or the first field out of range (`path` names the script).
    fn validate(&self, path: &Path) -> Result<(), ScriptError> {
        let bad = |field: &str, msg: String| Err(ScriptError::value(path, field, msg));
        if !(self.display_hz.is_finite() && (10.0..=1000.0).contains(&self.display_hz)) {
            return bad(
                "display_hz",
                format!("must be 10 to 1000 Hz, got {}", self.display_hz),
            );
        }
        if !(self.duration.is_finite() && self.duration > 0.0) {
            return bad(
                "duration",
                format!("must be a positive time in s, got {}", self.duration),
            );
        }
        if self.eye_size.0 == 0 || self.eye_size.1 == 0 {
            return bad("eye_size", "both sides must be at least 1 pixel".into());
        }
        if self.render_every == 0 {
            return bad("render_every", "must be at least 1".into());
        }
        if !self.draw_eyes && !self.screenshots.is_empty() {
            return bad(
                "screenshots",
                "the eyes are not drawn (`draw_eyes: false`): nothing to save".into(),
            );
        }
        if !(self.ipd.is_finite() && (0.0..0.2).contains(&self.ipd)) {
            return bad("ipd", format!("must be 0 to 0.2 m, got {}", self.ipd));
        }
        let f = self.fov;
        if !(f.left < f.right && f.down < f.up)
            || [f.left, f.right, f.up, f.down]
                .iter()
                .any(|a| !a.is_finite() || a.abs() >= 1.5)
        {
            return bad(
                "fov",
                "needs left < right, down < up, each within ±1.5 rad".into(),
            );
        }
        if self.head.is_empty() {
            return bad("head", "needs at least one key".into());
        }
        check_times(path, "head", self.head.iter().map(|k| k.t))?;
        check_times(path, "left", self.left.iter().map(|k| k.t))?;
        check_times(path, "trigger", self.trigger.iter().map(|k| k.0))?;
        check_times(path, "squeeze", self.squeeze.iter().map(|k| k.0))?;
        check_times(path, "stick", self.stick.iter().map(|k| k.0))?;
        check_times(path, "faults", self.faults.iter().map(|k| k.0))?;
        if let Some(RightTrack::Grip(keys)) = &self.right {
            check_times(path, "right", keys.iter().map(|k| k.t))?;
        }
        Ok(())
    }

    /// Display period, s.
    pub fn period(&self) -> f64 {
        1.0 / self.display_hz
    }

    /// The two eyes (left, right) for head pose `head`: offset ±ipd/2 along the head's x.
    pub fn eyes(&self, head: XrPose) -> [(XrPose, Fov); 2] {
        let f = self.fov;
        let left = Fov {
            left: f.left,
            right: f.right,
            up: f.up,
            down: f.down,
        };
        let right = Fov {
            left: -f.right,
            right: -f.left,
            ..left
        };
        let at = |dx: f32| {
            XrPose::new(
                head.position + head.orientation * Vec3::new(dx, 0.0, 0.0),
                head.orientation,
            )
        };
        [(at(-self.ipd / 2.0), left), (at(self.ipd / 2.0), right)]
    }
}

/// Ok, or the first key of `field` (named `field[i].t`) whose time is not finite or runs
/// backwards.
fn check_times(
    path: &Path,
    field: &str,
    times: impl Iterator<Item = f64>,
) -> Result<(), ScriptError> {
    let mut last = f64::NEG_INFINITY;
    for (i, t) in times.enumerate() {
        if !t.is_finite() || t < last {
            return Err(ScriptError::value(
                path,
                &format!("{field}[{i}].t"),
                format!("times must be finite and non-decreasing, got {t} after {last}"),
            ));
        }
        last = t;
    }
    Ok(())
}

/// The pose of stage keys at `t` (linear position, slerp orientation), or `None`
/// outside their time span.
pub fn stage_pose_at(keys: &[StageKey], t: f64) -> Option<XrPose> {
    let first = keys.first()?;
    let last = keys.last()?;
    if t < first.t || t > last.t {
        return None;
    }
    let i = keys.partition_point(|k| k.t <= t).saturating_sub(1);
    let a = keys[i];
    let Some(b) = keys.get(i + 1) else {
        return Some(XrPose::new(a.position, a.orientation));
    };
    let s = if b.t > a.t {
        ((t - a.t) / (b.t - a.t)) as f32
    } else {
        1.0
    };
    Some(XrPose::new(
        a.position.lerp(b.position, s),
        a.orientation.slerp(b.orientation, s),
    ))
}

/// A piecewise-linear track at `t` (held outside its keys; `zero` without keys).
pub fn track_at<T>(keys: &[(f64, T)], t: f64, zero: T) -> T
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let Some(first) = keys.first() else {
        return zero;
    };
    if t <= first.0 {
        return first.1;
    }
    let i = keys.partition_point(|k| k.0 <= t) - 1;
    match keys.get(i + 1) {
        None => keys[i].1,
        Some(b) => {
            let a = keys[i];
            let s = ((t - a.0) / (b.0 - a.0)) as f32;
            a.1 * (1.0 - s) + b.1 * s
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracks_interpolate_and_eyes_straddle_the_head() {
        let keys = [
            StageKey {
                t: 0.0,
                position: Vec3::ZERO,
                orientation: Quat::IDENTITY,
            },
            StageKey {
                t: 1.0,
                position: Vec3::new(1.0, 0.0, 0.0),
                orientation: Quat::IDENTITY,
            },
        ];
        assert_eq!(
            stage_pose_at(&keys, 0.25).unwrap().position,
            Vec3::new(0.25, 0.0, 0.0)
        );
        assert!(stage_pose_at(&keys, 1.5).is_none());
        assert_eq!(track_at(&[(0.0, 0.0f32), (1.0, 1.0)], 0.5, 0.0), 0.5);
        assert_eq!(track_at(&[(0.0, 0.2f32)], 3.0, 0.0), 0.2);
        assert_eq!(track_at::<f32>(&[], 3.0, 0.0), 0.0);
        let s: HeadsetScript =
            ron::from_str("(duration: 1.0, head: [(t: 0.0, position: (0.0, 1.5, 0.0))])").unwrap();
        assert_eq!(s.eye_size, QUEST3_EYE);
        let [l, r] = s.eyes(XrPose::new(Vec3::new(0.0, 1.5, 0.0), Quat::IDENTITY));
        assert!((r.0.position.x - l.0.position.x - 0.063).abs() < 1e-6);
        assert_eq!(l.1.left, -r.1.right);
    }

    #[test]
    fn bad_fields_are_named_with_the_file() {
        let path = Path::new("s.ron");
        let e = HeadsetScript::parse(
            "(duration: -1.0, head: [(t: 0.0, position: (0.0, 1.5, 0.0))])",
            path,
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("s.ron: duration: must be"), "{e}");
        let e = HeadsetScript::parse(
            "(duration: 1.0, head: [(t: 1.0, position: (0.0, 1.5, 0.0)), (t: 0.5, position: (0.0, 1.5, 0.0))])",
            path,
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("s.ron: head[1].t: times must be"), "{e}");
        let e = HeadsetScript::parse("(duration: 1.0,", path).unwrap_err();
        assert!(matches!(e, ScriptError::Syntax(_)), "{e}");
    }
}
