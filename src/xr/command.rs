//! What the display and the simulation hand each other: the display's newest tool
//! command (the scalpel pose sampled at a frame's predicted display time, the trigger,
//! reset and pause), the command the session makes of it for the body, and what a display
//! frame's simulation did.

use incise_sim::contact::ToolPose;

use crate::sim_body::ToolInput;

/// The display's orders for the simulation, newest wins.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolCommand {
    /// The display frame that sampled it.
    pub frame: u64,
    /// That frame's predicted display time, s: the time `pose` was sampled for.
    pub display_time: f64,
    /// The scalpel (sim world) while the controller is tracked.
    pub pose: Option<ToolPose>,
    /// Whether the blade cuts (trigger held, or a played stroke).
    pub engaged: bool,
    /// Whether the simulation is paused (menu).
    pub paused: bool,
    /// Resets asked so far (A presses that start the scene over).
    pub resets: u64,
}

/// The newest command a simulation frame was stepped with: its display frame and
/// predicted display time, s.
pub type CommandStamp = (u64, f64);

/// A display frame's orders for the body: the tool as the session decided it, whether
/// the controller was tracked (its pose is recorded then), pause and resets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyCommand {
    /// The tool for the frames stepped with this command.
    pub tool: ToolInput,
    /// Whether the controller was tracked.
    pub tracked: bool,
    /// Whether the simulation is paused.
    pub paused: bool,
    /// Resets asked so far.
    pub resets: u64,
    /// The display frame and its predicted display time.
    pub stamp: CommandStamp,
}

/// What one display frame's simulation did.
#[derive(Debug, Clone, Copy, Default)]
pub struct Advanced {
    /// Simulation frames completed since the previous display frame.
    pub sim_frames: u32,
    /// Substeps per simulation frame (1 for a method that has none).
    pub substeps: u32,
    /// Wall time of the simulation, ms (the thread: of its latest frame).
    pub sim_ms: f64,
    /// Contact force to vibrate with, N.
    pub tool_force: f32,
}
