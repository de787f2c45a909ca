//! The body of a method session (any method but XPBD), stepped inside each display frame
//! up to the frame's display time, or on its own thread ([`MethodThread`]) that the
//! display hands the frame's tool command and draws the newest frame of.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use incise_sim::contact::ToolPose;

use super::method_thread::{MethodCommand, MethodThread};
use super::sim_mode::SimMode;
use super::sim_state::{Advanced, CommandStamp};
use super::sim_thread::MAX_CATCH_UP;
use crate::pictures::tet_drawing::TetDrawing;
use crate::scene::Method;
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{TetView, ToolInput};

/// The body of a session: stepped inside the display frame, or on its own thread.
pub enum Stepper {
    /// In the frame: the display waits for the steps.
    InFrame {
        /// The body and its report.
        body: Box<RecordedBody>,
        /// Sleep this long after every body frame (testing aid).
        slow: Duration,
        /// The newest command the body was stepped with.
        last: Option<CommandStamp>,
    },
    /// On a thread; the display draws its newest frame.
    Thread {
        /// The thread.
        thread: MethodThread,
        /// The frame count of the frame shown.
        shown: usize,
        /// The newest command the frame shown was stepped with.
        last: Option<CommandStamp>,
    },
}

/// What a display frame's stepping did.
pub struct Step {
    /// The frame's simulation, as the frame log has it (one body step a frame: substeps
    /// 1).
    pub done: Advanced,
    /// The body's tets when a new frame is to be shown.
    pub view: Option<TetView>,
    /// Simulated time given up by a body stepped in the frame slower than real time, s.
    pub given_up: f64,
    /// Where the body shown draws its scalpel ([`crate::sim_body::SimBody::scalpel_pose`]).
    pub scalpel: Option<ToolPose>,
}

impl Stepper {
    /// Open `scene`'s body as `mode` says (slowed by `slow` a frame), writing its report
    /// to `out` at the end; the body and its first drawing.
    pub fn open(
        scene: &Path,
        out: &Path,
        mode: SimMode,
        slow: Duration,
    ) -> Result<(Stepper, TetDrawing)> {
        let (stepper, view) = match mode {
            SimMode::InFrame => {
                let body = Box::new(RecordedBody::open(scene)?);
                let view = body.body.tet_view();
                (
                    Stepper::InFrame {
                        body,
                        slow,
                        last: None,
                    },
                    view,
                )
            }
            SimMode::Thread => {
                let mut thread = MethodThread::spawn(scene, out.join("report.json"), slow)?;
                let first = thread.latest()?;
                let shown = first.frames;
                let view = first.view.clone();
                (
                    Stepper::Thread {
                        thread,
                        shown,
                        last: None,
                    },
                    view,
                )
            }
        };
        let drawing =
            TetDrawing::new(view).with_context(|| format!("{}: drawing", scene.display()))?;
        Ok((stepper, drawing))
    }

    /// Step the body, or hand its thread the frame's command (`stamp`), up to simulated
    /// time `until` with `tool`; in the frame, `after` sees the body after each frame.
    pub fn advance(
        &mut self,
        tool: ToolInput,
        until: f64,
        stamp: CommandStamp,
        after: &mut dyn FnMut(&RecordedBody) -> Result<()>,
    ) -> Result<Step> {
        let started = Instant::now();
        match self {
            Stepper::InFrame { body, slow, last } => {
                let dt = body.body.frame_dt();
                let mut stepped = 0;
                while body.body.time() + 0.5 * dt < until && stepped < MAX_CATCH_UP {
                    body.step(&tool).map_err(anyhow::Error::msg)?;
                    after(body)?;
                    std::thread::sleep(*slow);
                    stepped += 1;
                }
                if stepped > 0 {
                    *last = Some(stamp);
                }
                // A body slower than real time gives the owed time up rather than hold
                // every later display frame (as the XPBD frame pacer does).
                let owed = until - body.body.time() - 0.5 * dt;
                Ok(Step {
                    done: Advanced {
                        sim_frames: stepped,
                        substeps: 1,
                        sim_ms: started.elapsed().as_secs_f64() * 1e3,
                        tool_force: body.body.tool_force().map_or(0.0, |v| v.length()),
                    },
                    view: (stepped > 0).then(|| body.body.tet_view()),
                    given_up: owed.max(0.0),
                    scalpel: body.body.scalpel_pose(),
                })
            }
            Stepper::Thread {
                thread,
                shown,
                last,
            } => {
                thread.post(MethodCommand { tool, until, stamp });
                let s = thread.latest()?;
                let fresh = s.frames.saturating_sub(*shown);
                *shown = s.frames;
                *last = s.command;
                Ok(Step {
                    done: Advanced {
                        sim_frames: fresh as u32,
                        substeps: 1,
                        sim_ms: s.step_ms,
                        tool_force: s.force,
                    },
                    view: (fresh > 0).then(|| s.view.clone()),
                    given_up: 0.0,
                    scalpel: s.scalpel,
                })
            }
        }
    }

    /// The newest command the body shown was stepped with (for the tool-to-tissue
    /// latency).
    pub fn last_command(&self) -> Option<CommandStamp> {
        match self {
            Stepper::InFrame { last, .. } | Stepper::Thread { last, .. } => *last,
        }
    }

    /// The body's method and where it runs.
    pub fn body(&self) -> Result<(Method, String)> {
        match self {
            Stepper::InFrame { body, .. } => Ok((body.body.method(), body.body.device())),
            Stepper::Thread { thread, .. } => thread.body(),
        }
    }

    /// Body frames stepped so far.
    pub fn frames(&self) -> usize {
        match self {
            Stepper::InFrame { body, .. } => body.frames(),
            Stepper::Thread { thread, .. } => thread.frames(),
        }
    }

    /// Close the body, writing its `report.json` into `out`: the report's summary line
    /// and the frames the body stepped.
    pub fn close(self, out: &Path) -> Result<(String, usize)> {
        match self {
            Stepper::InFrame { body, .. } => {
                let frames = body.frames();
                Ok((body.close(Some(&out.join("report.json")))?, frames))
            }
            Stepper::Thread { thread, .. } => thread.finish(),
        }
    }
}
