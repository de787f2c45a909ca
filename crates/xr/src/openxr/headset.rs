//! What the frame loop needs from a headset, so one loop drives both the OpenXR session
//! and the simulated headset: frames with predicted display times, eye poses and fields
//! of view, controller state, eye render targets, and vibration.

use super::backdrop::Backdrop;
use super::controls::ControllerState;
use super::error::XrError;
use super::haptics::HapticPulse;
use super::lifecycle::{ExitReason, SessionPhase};
use super::pose::{Fov, XrPose};
use crate::device::RenderDevice;

/// One display frame, begun.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadsetFrame {
    /// When the frame will be shown, s (the runtime's predicted display time).
    pub display_time: f64,
    /// Time between displayed frames, s (1/72, 1/90, 1/120 on Quest 3).
    pub display_period: f64,
    /// Whether to render it (the session is visible); else end it with no layers.
    pub should_render: bool,
    /// Each eye's pose (stage space) and field of view, in [`super::eye::EYE_ORDER`].
    pub eyes: [(XrPose, Fov); 2],
    /// The controllers at the display time.
    pub controllers: ControllerState,
    /// Whether the app has input focus (controller input counts).
    pub focused: bool,
}

/// What `next_frame` found.
#[derive(Debug, Clone, PartialEq)]
pub enum FrameEvent {
    /// A frame was begun.
    Frame(Box<HeadsetFrame>),
    /// The session is not running yet (or stopped for now): poll again.
    Idle,
    /// The session ended.
    Ended(ExitReason),
}

/// A headset the frame loop can drive.
pub trait Headset {
    /// The device that renders into the eye targets.
    fn device(&self) -> &RenderDevice;
    /// Eye target size, pixels.
    fn eye_size(&self) -> (u32, u32);
    /// Eye target colour format.
    fn format(&self) -> wgpu::TextureFormat;
    /// What this headset is (runtime name, or "simulated").
    fn describe(&self) -> String;
    /// What the organ is seen against (sets the eye images' clear colour and alpha).
    fn backdrop(&self) -> Backdrop;
    /// Whether the eye images are drawn (false: a simulated headset measuring the
    /// simulation alone, `draw_eyes: false`).
    fn draws_eyes(&self) -> bool {
        true
    }
    /// Poll events, wait for the next frame and begin it.
    fn next_frame(&mut self) -> Result<FrameEvent, XrError>;
    /// Acquire the begun frame's eye targets: one view per eye in eye order.
    fn acquire(&mut self) -> Result<[wgpu::TextureView; 2], XrError>;
    /// The frame's GPU work is submitted: release its targets (if acquired) and end it,
    /// showing the rendered eyes when `rendered`.
    fn end_frame(&mut self, rendered: bool) -> Result<(), XrError>;
    /// Vibrate the right controller with `pulse`, or stop it.
    fn vibrate(&mut self, pulse: Option<HapticPulse>) -> Result<(), XrError>;
    /// Ask to end the session (it ends through the lifecycle).
    fn request_exit(&mut self) -> Result<(), XrError>;
    /// The session states so far, in order, from the initial IDLE.
    fn session_states(&self) -> &[SessionPhase];
}
