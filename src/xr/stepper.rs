//! Where a headset session's body is stepped: inside each display frame (the display
//! waits; the frame pacer's frames for the frame's predicted display time, substeps cut
//! before time when late), or on its own thread ([`SimThread`]), which the display hands
//! each frame's command and draws the newest frame of.

use std::sync::Arc;
use std::time::Instant;

use super::pacing::FramePacer;
use anyhow::Result;
use incise_sim::contact::ToolPose;
use incise_xr::openxr::HeadsetFrame;

use super::command::{Advanced, BodyCommand, CommandStamp};
use super::live_sim::{LiveSim, Stepped};
use super::sim_thread::{MAX_CATCH_UP, Published, SimThread, ThreadEnd};
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{BodyView, CutView};

/// Fraction of a display period a body stepped in the frame may use.
pub const SIM_BUDGET: f64 = 0.5;

/// What a body stepped in the frame tells the session's exercise: each frame stepped, a
/// failed frame (before the scene starts over) and the fresh scene.
pub trait FrameHook {
    /// After a completed frame stepped with `cmd`.
    fn after_step(&mut self, body: &RecordedBody, cmd: &BodyCommand) -> Result<()>;
    /// The body failed (`why`) and is about to be reset.
    fn on_failure(&mut self, body: &RecordedBody, why: &str) -> Result<()>;
    /// The scene was started over.
    fn after_reset(&mut self, body: &mut RecordedBody) -> Result<()>;
}

/// The body of a session: stepped inside the display frame, or on its own thread.
pub enum Stepper {
    /// In the frame: the display waits for the steps.
    InFrame {
        /// The body.
        live: Box<LiveSim>,
        /// Its pacer.
        pacer: FramePacer,
    },
    /// On a thread; the display draws its newest frame.
    Thread {
        /// The thread.
        thread: SimThread,
        /// The frame on show.
        current: Option<Arc<Published>>,
    },
}

/// What a display frame's stepping did.
pub struct Step {
    /// The frame's simulation, as the frame log has it.
    pub done: Advanced,
    /// The body's frame when a new one is to be shown.
    pub view: Option<BodyView>,
    /// Where the body shown draws its scalpel.
    pub scalpel: Option<ToolPose>,
}

/// What the stepping did over the session.
pub struct SteppingEnd {
    /// The body.
    pub live: LiveSim,
    /// Simulated time given up, s.
    pub dropped_time: f64,
    /// Wall time of the simulation (the thread: from the first command), s; `None`: the
    /// display loop's.
    pub wall_s: Option<f64>,
    /// The thread's failure, if the display did not see it.
    pub error: Option<anyhow::Error>,
}

impl Stepper {
    /// Step `live` in the frame (the scene's substeps kept when `nominal`).
    pub fn in_frame(live: LiveSim, nominal: bool) -> Stepper {
        let pacer = live.pacer(SIM_BUDGET, MAX_CATCH_UP, nominal);
        Stepper::InFrame {
            live: Box::new(live),
            pacer,
        }
    }

    /// Step `live` on its own thread.
    pub fn thread(live: LiveSim, nominal: bool) -> Result<Stepper> {
        Ok(Stepper::Thread {
            thread: SimThread::spawn(live, nominal)?,
            current: None,
        })
    }

    /// Step the body (or hand its thread `cmd`) for display frame `frame`; `previous` is
    /// the frame drawn last, `hook` sees each frame stepped in the frame.
    pub fn advance(
        &mut self,
        frame: &HeadsetFrame,
        cmd: BodyCommand,
        hook: &mut dyn FrameHook,
        previous: Option<&CutView>,
    ) -> Result<Step> {
        match self {
            Stepper::InFrame { live, pacer } => in_frame(live, pacer, frame, cmd, hook, previous),
            Stepper::Thread { thread, current } => {
                thread.post(cmd);
                let s = thread.latest()?;
                let before = current.as_ref().map_or(0, |c| c.frames);
                let fresh = !current.as_ref().is_some_and(|c| Arc::ptr_eq(c, &s));
                let step = Step {
                    done: Advanced {
                        sim_frames: s.frames.saturating_sub(before) as u32,
                        substeps: s.substeps,
                        sim_ms: s.step_ms,
                        tool_force: s.force,
                    },
                    view: fresh.then(|| s.view.clone()),
                    scalpel: s.scalpel,
                };
                *current = Some(s);
                Ok(step)
            }
        }
    }

    /// After the display frame: the body stepped in the frame does the next frame's
    /// pose-free work ([`LiveSim::prepare_next`]); the thread does its own.
    pub fn after_frame(&mut self) {
        if let Stepper::InFrame { live, .. } = self {
            live.prepare_next();
        }
    }

    /// A pressed: the body stepped in the frame starts over now (its fresh frame
    /// returned); the thread is told with the next command (`None`).
    pub fn reset(&mut self, hook: &mut dyn FrameHook) -> Result<Option<BodyView>> {
        match self {
            Stepper::InFrame { live, .. } => {
                live.reset()?;
                hook.after_reset(&mut live.body)?;
                Ok(Some(live.view(None)))
            }
            Stepper::Thread { .. } => Ok(None),
        }
    }

    /// The body, when it is stepped in the frame (an exercise reads it).
    pub fn body(&mut self) -> Option<&mut RecordedBody> {
        match self {
            Stepper::InFrame { live, .. } => Some(&mut live.body),
            Stepper::Thread { .. } => None,
        }
    }

    /// The newest command the body shown was stepped with (tool-to-tissue latency).
    pub fn last_command(&self) -> Option<CommandStamp> {
        match self {
            Stepper::InFrame { live, .. } => live.last_command,
            Stepper::Thread { current, .. } => current.as_ref().and_then(|c| c.command),
        }
    }

    /// Whether a played stroke has been played to its end.
    pub fn stroke_done(&self) -> bool {
        match self {
            Stepper::InFrame { live, .. } => live.stroke_done(),
            Stepper::Thread { current, .. } => current.as_ref().is_some_and(|c| c.stroke_done),
        }
    }

    /// Stop stepping: the body back, with what the stepping did.
    pub fn finish(self) -> Result<SteppingEnd> {
        match self {
            Stepper::InFrame { live, pacer } => Ok(SteppingEnd {
                live: *live,
                dropped_time: pacer.dropped_time(),
                wall_s: None,
                error: None,
            }),
            Stepper::Thread { thread, .. } => {
                let ThreadEnd {
                    live,
                    dropped_time,
                    wall_s,
                    error,
                } = thread.finish()?;
                Ok(SteppingEnd {
                    live,
                    dropped_time,
                    wall_s: Some(wall_s),
                    error,
                })
            }
        }
    }
}

/// The pacer's frames of `live` for display frame `frame` with `cmd`; a failed frame is
/// told to `hook` and the scene starts over.
fn in_frame(
    live: &mut LiveSim,
    pacer: &mut FramePacer,
    frame: &HeadsetFrame,
    cmd: BodyCommand,
    hook: &mut dyn FrameHook,
    previous: Option<&CutView>,
) -> Result<Step> {
    let mut plan = pacer.plan(frame.display_time, frame.display_period);
    if cmd.paused || live.stroke_done() {
        plan.sim_frames = 0;
    }
    live.set_substeps(plan.substeps)?;
    let started = Instant::now();
    let mut done = Advanced {
        substeps: live.substeps(),
        ..Advanced::default()
    };
    let mut reset = false;
    for _ in 0..plan.sim_frames {
        if live.stroke_done() {
            break;
        }
        match live.step(&cmd)? {
            Stepped::Done => {
                done.sim_frames += 1;
                done.tool_force = done.tool_force.max(live.force);
                hook.after_step(&live.body, &cmd)?;
            }
            Stepped::Failed(e) => {
                // The body gave up (a tet inverted too long): the frame is rolled back;
                // start the scene again rather than end the trainee's session.
                eprintln!("xr: {e}; resetting the scene");
                hook.on_failure(&live.body, &e)?;
                live.reset()?;
                hook.after_reset(&mut live.body)?;
                reset = true;
                break;
            }
        }
    }
    done.sim_ms = started.elapsed().as_secs_f64() * 1e3;
    if plan.sim_frames > 0 {
        pacer.record(plan, done.sim_ms * 1e-3);
    }
    if done.sim_frames == 0 && !reset {
        // A display frame between simulation frames (one in six at 72 Hz on a 60 Hz
        // scene): the tissue still pushes as it did, as the thread's latest frame does;
        // a zero here stopped the controller's vibration a frame in six while cutting.
        done.tool_force = live.force;
    }
    let shown = done.sim_frames > 0 || reset;
    Ok(Step {
        done,
        view: shown.then(|| live.view(previous)),
        scalpel: live.body.body.scalpel_pose(),
    })
}
