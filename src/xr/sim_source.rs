//! The simulation as the display loop sees it, in either mode: hand it the frame's tool
//! command, and get the state to render, the force to vibrate with and the newest command
//! that state includes (for the tool-to-tissue latency).

use std::sync::Arc;

use anyhow::Result;
use incise_sim::contact::ToolPose;
use incise_sim::skin::Skin;
use incise_xr::openxr::HeadsetFrame;
use incise_xr::{BodyState, RenderDevice};

use super::exercise::XrExercise;
use super::in_frame::InFrameSim;
use super::sim_state::{Advanced, CommandStamp, SimState, ToolCommand};
use super::sim_thread::SimLink;
use super::xr_body::XrBody;
use crate::pictures::screenshots::stress_scale;

/// The display side of the simulation thread.
pub struct ThreadSim<'s> {
    link: &'s SimLink,
    current: Option<Arc<SimState>>,
    resets: u64,
}

impl<'s> ThreadSim<'s> {
    /// The display's end of `link`.
    pub fn new(link: &'s SimLink) -> Self {
        ThreadSim {
            link,
            current: None,
            resets: 0,
        }
    }

    /// Post `cmd` (with the resets asked so far) and take the newest state; the thread's
    /// error, if it stopped.
    fn advance(&mut self, mut cmd: ToolCommand) -> Result<Advanced> {
        if let Some(e) = self.link.take_failure() {
            return Err(e);
        }
        cmd.resets = self.resets;
        self.link.commands.put(cmd);
        let before = self.current.as_ref().map_or(0, |s| s.frame);
        self.current = self.link.states.get();
        Ok(match &self.current {
            Some(s) => Advanced {
                sim_frames: s.frame.saturating_sub(before) as u32,
                substeps: s.substeps,
                sim_ms: s.step_ms,
                tool_force: s.tool_force,
            },
            None => Advanced::default(),
        })
    }
}

/// What a display frame renders: the body, the stress overlay's full scale, Pa, and the
/// scalpel's pose with whether it is tracked.
pub struct RenderInput<'a> {
    /// The body.
    pub body: BodyState<'a>,
    /// Stress overlay full scale, Pa.
    pub stress_max: f32,
    /// The scalpel.
    pub tool: (ToolPose, bool),
}

/// The session's simulation.
pub enum Sim<'a, 's, 'x> {
    /// Stepped in the display frame.
    InFrame(&'a mut InFrameSim<'s, 'x>),
    /// On its own thread.
    Thread(&'a mut ThreadSim<'s>),
}

impl Sim<'_, '_, '_> {
    /// Before the first frame: an exercise's first attempt, a played stroke's first pose
    /// (the thread places its stroke itself).
    pub fn start(
        &mut self,
        exercise: Option<&mut XrExercise>,
        skin: &Skin,
        dev: &RenderDevice,
    ) -> Result<()> {
        let Sim::InFrame(s) = self else {
            return Ok(());
        };
        if let Some(ex) = exercise {
            ex.start(s.xr, skin, dev)?;
        }
        s.stepper.start(s.xr)
    }

    /// Step (in the frame) or post (to the thread) this display frame's command.
    pub fn advance(
        &mut self,
        frame: &HeadsetFrame,
        cmd: ToolCommand,
        exercise: Option<&mut XrExercise>,
        skin: &Skin,
        dev: &RenderDevice,
    ) -> Result<Advanced> {
        match self {
            Sim::InFrame(s) => s.advance(frame, &cmd, exercise, skin, dev),
            Sim::Thread(t) => t.advance(cmd),
        }
    }

    /// A pressed: the in-frame body resets at once (an exercise finishes its attempt
    /// first); the thread is asked with the next command.
    pub fn on_a(
        &mut self,
        exercise: Option<&mut XrExercise>,
        skin: &Skin,
        dev: &RenderDevice,
    ) -> Result<()> {
        match self {
            Sim::InFrame(s) => s.on_a(exercise, skin, dev),
            Sim::Thread(t) => {
                t.resets += 1;
                Ok(())
            }
        }
    }

    /// The body, when it is stepped in the frame (exercises need it).
    pub fn body(&mut self) -> Option<&mut XrBody> {
        match self {
            Sim::InFrame(s) => Some(s.xr),
            Sim::Thread(_) => None,
        }
    }

    /// The state to render (`None`: the thread has published none yet).
    pub fn render_input(&mut self) -> Option<RenderInput<'_>> {
        match self {
            Sim::InFrame(s) => {
                let (xr, pinned) = s.render_state();
                let solver = xr.solver();
                Some(RenderInput {
                    body: BodyState::of_solver(solver, pinned),
                    stress_max: stress_scale(solver),
                    tool: xr.tool(),
                })
            }
            Sim::Thread(t) => t.current.as_deref().map(|s| RenderInput {
                body: s.body(),
                stress_max: s.stress_max,
                tool: s.tool,
            }),
        }
    }

    /// The newest tool command the state on show was stepped with.
    pub fn shown_command(&self) -> Option<CommandStamp> {
        match self {
            Sim::InFrame(s) => s.stepper.last_command,
            Sim::Thread(t) => t.current.as_ref().and_then(|s| s.command),
        }
    }

    /// Whether a played stroke has been played to its end.
    pub fn stroke_done(&self) -> bool {
        match self {
            Sim::InFrame(s) => s.stepper.stroke_done(),
            Sim::Thread(t) => t.current.as_ref().is_some_and(|s| s.stroke_done),
        }
    }
}
