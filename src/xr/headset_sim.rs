//! The simulation of a headset session as the one display loop ([`super::frame_loop`])
//! drives it, whatever the method: hand it each display frame's tool command, press A,
//! and take the picture to draw both eyes from. The session of a body of any method
//! ([`super::session`]) implements it.

use anyhow::Result;
use glam::Mat4;
use incise_sim::contact::ToolPose;
use incise_xr::openxr::HeadsetFrame;
use incise_xr::openxr::tray::Tray;
use incise_xr::{BodyState, Renderer, SurfaceLine};

use super::command::{Advanced, CommandStamp, ToolCommand};

/// What a display frame draws: the body with the renderer built for it, and what goes
/// with it.
pub struct Picture<'a> {
    /// The renderer of the body's current topology.
    pub renderer: &'a mut Renderer,
    /// The body.
    pub body: BodyState<'a>,
    /// Full scale of the heat map (the method's own quantity).
    pub heat_max: f32,
    /// The scalpel, where it is drawn (`None`: not tracked, or the scene's script holds
    /// a tool that is not drawn: XPBD's, or rheology's indenter).
    pub tool: Option<ToolPose>,
    /// Lines on the tissue (an exercise's plan).
    pub lines: Vec<SurfaceLine>,
    /// The result card's placement, once there is one.
    pub panel: Option<Mat4>,
}

/// A headset session's simulation, stepped in the frame or on its own thread.
pub trait HeadsetSim {
    /// Whether the heat map shows from the start (the stick's button toggles it).
    fn heat_map_at_start(&self) -> bool;

    /// Before the first display frame (an exercise's first attempt, a played stroke's
    /// first pose).
    fn start(&mut self) -> Result<()>;

    /// A pressed: an exercise finishes its attempt, or the scene starts over.
    fn on_a(&mut self) -> Result<()>;

    /// Step (or hand the thread) this display frame's tool command.
    fn advance(&mut self, frame: &HeadsetFrame, cmd: &ToolCommand) -> Result<Advanced>;

    /// After the display frame went to the runtime: the body stepped in the frame does the
    /// next frame's work that needs no pose now, off the time between the next pose and
    /// its display ([`crate::sim_body::SimBody::prepare_next_frame`]; the thread does the
    /// same after each frame it publishes).
    fn after_frame(&mut self) {}

    /// Whether the controller vibrates with the tool force this frame.
    fn vibrates(&self, cmd: &ToolCommand) -> bool {
        cmd.engaged
    }

    /// What to draw, with the tray and the head (between the eyes) for the result card;
    /// `None` while there is nothing to show yet.
    fn picture(&mut self, tray: &Tray, head: glam::Vec3) -> Result<Option<Picture<'_>>>;

    /// The newest tool command the body on show was stepped with (tool-to-tissue
    /// latency).
    fn shown_command(&self) -> Option<CommandStamp>;

    /// Whether a played stroke has been played to its end (the session then ends).
    fn stroke_done(&self) -> bool {
        false
    }

    /// The session is over, however it ended: save an attempt the blade touched.
    fn end(&mut self) -> Result<()>;
}
