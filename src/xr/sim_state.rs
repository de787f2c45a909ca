//! What the display and the simulation hand each other: the display's newest tool
//! command (the scalpel pose sampled at a frame's predicted display time, the trigger,
//! reset and pause), and the simulation's latest completed state (what the display
//! renders and vibrates from).

use std::sync::Arc;

use incise_sim::contact::ToolPose;
use incise_sim::cutting::CutState;
use incise_xr::BodyState;
use incise_xr::frame::pinned_nodes;

use super::xr_body::XrBody;
use crate::pictures::screenshots::stress_scale;

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

/// What one display frame's simulation did.
#[derive(Debug, Clone, Copy, Default)]
pub struct Advanced {
    /// Simulation frames completed since the previous display frame.
    pub sim_frames: u32,
    /// Substeps per simulation frame.
    pub substeps: u32,
    /// Wall time of the simulation, ms (the thread: of its latest frame).
    pub sim_ms: f64,
    /// Contact force to vibrate with, N.
    pub tool_force: f32,
}

/// The newest command a simulation frame was stepped with: its display frame and
/// predicted display time, s.
pub type CommandStamp = (u64, f64);

/// A completed simulation frame, as the display needs it.
pub struct SimState {
    /// Simulation frames stepped in the session so far.
    pub frame: u64,
    /// Simulated time, s.
    pub sim_time: f64,
    /// Node positions, m.
    pub positions: Vec<glam::Vec3>,
    /// Live tets and visible faces (shared until the cut changes).
    pub cut: Arc<CutState>,
    /// von Mises stress per tet, Pa.
    pub von_mises: Vec<f32>,
    /// Pinned nodes (shared until the scene is rebuilt).
    pub pinned: Arc<Vec<u32>>,
    /// The stress overlay's full scale, Pa.
    pub stress_max: f32,
    /// The scalpel's pose and whether the controller was tracked.
    pub tool: (ToolPose, bool),
    /// Contact force of this frame, N (drives the vibration).
    pub tool_force: f32,
    /// Substeps the frame ran.
    pub substeps: u32,
    /// Wall time of the frame's step, ms.
    pub step_ms: f64,
    /// The newest tool command the frame was stepped with.
    pub command: Option<CommandStamp>,
    /// A played stroke has been played to its end.
    pub stroke_done: bool,
}

impl SimState {
    /// The state of `xr` now (frame counters and stamps zero: the caller fills them in);
    /// `previous` lends its cut and pins when neither changed (same released count, the
    /// scene not `rebuilt` since).
    pub fn capture(xr: &XrBody, previous: Option<&SimState>, rebuilt: bool) -> SimState {
        let solver = xr.solver();
        let released = solver.cut().released_count();
        let kept = previous.filter(|p| !rebuilt && p.cut.released_count() == released);
        SimState {
            frame: 0,
            sim_time: 0.0,
            positions: solver.positions().to_vec(),
            cut: kept.map_or_else(|| Arc::new(solver.cut().clone()), |p| p.cut.clone()),
            von_mises: solver.von_mises().to_vec(),
            pinned: kept.map_or_else(|| Arc::new(pinned_nodes(solver)), |p| p.pinned.clone()),
            stress_max: stress_scale(solver),
            tool: xr.tool(),
            tool_force: 0.0,
            substeps: solver.params().substeps,
            step_ms: 0.0,
            command: None,
            stroke_done: false,
        }
    }

    /// The body to render.
    pub fn body(&self) -> BodyState<'_> {
        BodyState {
            positions: &self.positions,
            device_displacements: None,
            cut: &self.cut,
            von_mises: &self.von_mises,
            pinned: &self.pinned,
        }
    }
}
