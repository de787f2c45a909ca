//! One simulation frame of an XR session, the same on the simulation thread and in the
//! frame loop: the tool driven by the newest command (or a played stroke, in simulation
//! time), the testing aids (a NaN before a chosen frame, an artificially slow solver),
//! the step, and the scalpel's path recorded.

use std::time::{Duration, Instant};

use anyhow::Result;
use incise_scalpel::{Stroke, StrokeRecorder};
use incise_sim::contact::ToolPose;
use incise_sim::xpbd::FrameStats;

use super::sim_state::{CommandStamp, ToolCommand};
use super::xr_body::XrBody;

/// What became of a simulation frame.
pub enum Stepped {
    /// It completed.
    Done {
        /// Its statistics.
        stats: FrameStats,
        /// The scalpel's pose it was stepped with (when tracked).
        pose: Option<ToolPose>,
        /// Whether the scalpel cut (the trigger held; a played stroke outside its lifted
        /// spans).
        engaged: bool,
    },
    /// The solver gave up (the frame was rolled back); the caller resets the scene.
    Failed(anyhow::Error),
}

/// Testing aids of the simulation.
#[derive(Debug, Clone, Copy, Default)]
pub struct SimFaults {
    /// A NaN in the solver just before this simulation frame.
    pub nan_at: Option<u64>,
    /// A panic in the simulation just before this simulation frame.
    pub panic_at: Option<u64>,
    /// Sleep added to every simulation frame (an artificially slow solver).
    pub slow: Duration,
}

/// Steps frames and keeps the session's simulation counters.
pub struct SimStepper<'a> {
    stroke: Option<&'a Stroke>,
    sim_dt: f64,
    faults: SimFaults,
    recorder: Option<StrokeRecorder>,
    /// Simulated time, s.
    pub sim_time: f64,
    /// Frames stepped.
    pub frames: u64,
    /// Largest contact force, N.
    pub max_force: f32,
    /// Frames the solver failed.
    pub failures: u32,
    /// The newest command a completed frame was stepped with.
    pub last_command: Option<CommandStamp>,
    /// Wall time of the last frame, ms.
    pub last_ms: f64,
}

impl<'a> SimStepper<'a> {
    /// A stepper of `sim_dt` frames, playing `stroke` if given, recording the scalpel's
    /// path when `record`.
    pub fn new(stroke: Option<&'a Stroke>, sim_dt: f64, record: bool, faults: SimFaults) -> Self {
        SimStepper {
            stroke,
            sim_dt,
            faults,
            recorder: record.then(StrokeRecorder::new),
            sim_time: 0.0,
            frames: 0,
            max_force: 0.0,
            failures: 0,
            last_command: None,
            last_ms: 0.0,
        }
    }

    /// Place the blade where a played stroke starts (as `incise run --stroke` does).
    pub fn start(&self, xr: &mut XrBody) -> Result<()> {
        match self.stroke {
            Some(s) => xr.drive_tool(Some(s.pose_at(0.0)), !s.lifted_at(0.0)),
            None => Ok(()),
        }
    }

    /// Whether a played stroke has been played to its end (no more frames are stepped).
    pub fn stroke_done(&self) -> bool {
        self.stroke.is_some_and(|s| self.sim_time >= s.end_time())
    }

    /// Step one frame of `xr` with `cmd` (a played stroke: its pose at the end of the
    /// frame, engaged but in its lifted spans). Errors other than a solver failure end the
    /// session.
    pub fn step(&mut self, xr: &mut XrBody, cmd: &ToolCommand) -> Result<Stepped> {
        let started = Instant::now();
        let (pose, engaged) = match self.stroke {
            Some(s) => {
                let t = self.sim_time + self.sim_dt;
                (Some(s.pose_at(t)), !s.lifted_at(t))
            }
            None => (cmd.pose, cmd.engaged),
        };
        xr.drive_tool(pose, engaged)?;
        if self.faults.nan_at == Some(self.frames) {
            self.faults.nan_at = None;
            xr.body.inject_nan();
        }
        if self.faults.panic_at == Some(self.frames) {
            panic!("injected panic before simulation frame {}", self.frames);
        }
        let stats = match xr.step() {
            Ok(s) => s,
            Err(e) => {
                self.failures += 1;
                return Ok(Stepped::Failed(e));
            }
        };
        if !self.faults.slow.is_zero() {
            std::thread::sleep(self.faults.slow);
        }
        self.sim_time += self.sim_dt;
        self.frames += 1;
        self.max_force = self.max_force.max(stats.tool_force.length());
        self.last_command = Some((cmd.frame, cmd.display_time));
        self.last_ms = started.elapsed().as_secs_f64() * 1e3;
        if let (Some(r), Some(p)) = (&mut self.recorder, pose) {
            r.push_engaged(self.sim_time, p, engaged)?;
        }
        Ok(Stepped::Done {
            stats,
            pose,
            engaged,
        })
    }

    /// The recorded path as a stroke (none without two poses: a stroke needs two).
    pub fn recorded(&mut self) -> Result<Option<Stroke>> {
        match self.recorder.take() {
            Some(r) if r.len() >= 2 => Ok(Some(r.finish()?)),
            _ => Ok(None),
        }
    }
}
