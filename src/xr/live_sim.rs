//! The body of a headset session, stepped the same way whether its own thread
//! ([`super::sim_thread`]) or the display frame ([`super::stepper`]) steps it: the tool
//! the session decided (the controller's, the scene's script, or a played stroke the body
//! replays as `incise run --stroke` does), the testing aids (a NaN before a chosen frame,
//! a panic, an artificially slow body), the scalpel's path recorded for a replay, a
//! failed frame reported so the scene starts over, and substeps the pacer may cut.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::pacing::{FramePacer, PacingConfig};
use anyhow::Result;
use incise_scalpel::{Stroke, StrokeRecorder};

use super::command::{BodyCommand, CommandStamp};
use super::xr_report::{CutBox, cut_extent};
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{BodyView, CutView, Fault, OpenOptions, ToolInput};

/// Testing aids of the simulation.
#[derive(Debug, Clone, Copy, Default)]
pub struct SimFaults {
    /// A NaN in the body just before this simulation frame.
    pub nan_at: Option<u64>,
    /// A panic in the simulation just before this simulation frame.
    pub panic_at: Option<u64>,
    /// Sleep added to every simulation frame (an artificially slow body).
    pub slow: Duration,
}

/// What became of a simulation frame.
pub enum Stepped {
    /// It completed.
    Done,
    /// The body gave up (its frame rolled back), with why; the caller starts the scene
    /// over ([`LiveSim::reset`]).
    Failed(String),
}

/// How a session's body is opened, again on each reset.
#[derive(Clone)]
pub struct BodyOpener {
    /// The scene file.
    pub scene: PathBuf,
    /// The device, a hand on the tool, a played stroke.
    pub opts: OpenOptions,
}

impl BodyOpener {
    /// The scene's body as it loads.
    pub fn open(&self) -> Result<RecordedBody> {
        RecordedBody::open_with(&self.scene, &self.opts)
    }
}

/// A session's body and its counters.
pub struct LiveSim {
    /// The body and its report.
    pub body: RecordedBody,
    opener: BodyOpener,
    faults: SimFaults,
    /// A played stroke (the body plays it as its script).
    played: Option<Stroke>,
    recorder: Option<StrokeRecorder>,
    /// Simulated time of the session, s (across resets: the recorded stroke's clock).
    sim_time: f64,
    /// Simulation frames stepped in the session.
    pub frames: u64,
    /// Largest tool force, N.
    pub max_force: f32,
    /// Tool force of the last frame, N.
    pub force: f32,
    /// Frames the body failed (each followed by a reset).
    pub failures: u32,
    /// The newest command a completed frame was stepped with.
    pub last_command: Option<CommandStamp>,
    /// Wall time of the last frame, ms.
    pub last_ms: f64,
    /// Fewest substeps a frame ran (the scene's when the body has none to cut).
    pub min_substeps: u32,
}

impl LiveSim {
    /// Open the body `opener` names, replaying `played` (opened with it as the body's
    /// stroke).
    pub fn open(opener: BodyOpener, played: Option<Stroke>, faults: SimFaults) -> Result<LiveSim> {
        let body = opener.open()?;
        let min_substeps = body.body.substeps().map_or(1, |s| s.nominal);
        Ok(LiveSim {
            body,
            opener,
            faults,
            played,
            recorder: None,
            sim_time: 0.0,
            frames: 0,
            max_force: 0.0,
            force: 0.0,
            failures: 0,
            last_command: None,
            last_ms: 0.0,
            min_substeps,
        })
    }

    /// Record the scalpel's path from now on (a played stroke's, or the controller's
    /// while tracked).
    pub fn recording(mut self) -> LiveSim {
        self.recorder = Some(StrokeRecorder::new());
        self
    }

    /// The scene back as it loads (A, or after a failed frame).
    pub fn reset(&mut self) -> Result<()> {
        self.body = self.opener.open()?;
        self.force = 0.0;
        Ok(())
    }

    /// The frame length, s.
    pub fn dt(&self) -> f64 {
        self.body.body.frame_dt()
    }

    /// A frame pacer for this body: `budget` of each frame's time for the body, at most
    /// `max_frames` frames at once, substeps cut to the fewest stable ones unless
    /// `nominal`. A method without substeps steps its frames to the display's time
    /// whatever they cost (at most `max_frames` at once, the rest given up): fewer frames
    /// would slow its simulated time instead.
    pub fn pacer(&self, budget: f64, max_frames: u32, nominal: bool) -> FramePacer {
        let (n, fewest, budget) = match self.body.body.substeps() {
            Some(s) => (s.nominal, s.fewest, budget),
            None => (1, 1, f64::INFINITY),
        };
        FramePacer::new(PacingConfig {
            sim_dt: self.dt(),
            nominal_substeps: n,
            min_substeps: if nominal { n } else { fewest },
            budget_fraction: budget,
            max_sim_frames: max_frames,
        })
    }

    /// Run `substeps` a frame from now on, where the body has substeps.
    pub fn set_substeps(&mut self, substeps: u32) -> Result<()> {
        match self.body.body.substeps() {
            Some(s) if s.now != substeps => {
                self.body.body.set_substeps(substeps)?;
                self.min_substeps = self.min_substeps.min(substeps);
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// Substeps a frame now (1 for a method without).
    pub fn substeps(&self) -> u32 {
        self.body.body.substeps().map_or(1, |s| s.now)
    }

    /// Whether a played stroke has been played to its end (no more frames are stepped).
    pub fn stroke_done(&self) -> bool {
        (self.played.as_ref()).is_some_and(|s| self.body.body.time() >= s.end_time() - 1e-9)
    }

    /// Do the next frame's work that does not depend on the tool's pose now
    /// ([`crate::sim_body::SimBody::prepare_next_frame`]).
    pub fn prepare_next(&mut self) {
        self.body.body.prepare_next_frame();
    }

    /// Step one frame with `cmd` (a played stroke: the body's own script). Errors other
    /// than a failed body frame end the session.
    pub fn step(&mut self, cmd: &BodyCommand) -> Result<Stepped> {
        let started = Instant::now();
        if self.faults.nan_at == Some(self.frames) {
            self.faults.nan_at = None;
            self.body.body.inject(Fault::Nan)?;
        }
        if self.faults.panic_at == Some(self.frames) {
            panic!("injected panic before simulation frame {}", self.frames);
        }
        let tool = match self.played {
            Some(_) => ToolInput::Script,
            None => cmd.tool,
        };
        if let Err(e) = self.body.step(&tool) {
            self.failures += 1;
            return Ok(Stepped::Failed(e));
        }
        if !self.faults.slow.is_zero() {
            std::thread::sleep(self.faults.slow);
        }
        self.sim_time += self.dt();
        self.frames += 1;
        self.force = self.body.body.tool_force().map_or(0.0, |f| f.length());
        self.max_force = self.max_force.max(self.force);
        self.last_command = Some(cmd.stamp);
        self.last_ms = started.elapsed().as_secs_f64() * 1e3;
        self.record(cmd)?;
        Ok(Stepped::Done)
    }

    /// Keep the scalpel's pose of the frame just stepped: a played stroke's, or the
    /// controller's while tracked.
    fn record(&mut self, cmd: &BodyCommand) -> Result<()> {
        let Some(r) = &mut self.recorder else {
            return Ok(());
        };
        let t = self.body.body.time();
        let (pose, engaged) = match (&self.played, cmd.tool) {
            (Some(s), _) => (Some(s.pose_at(t)), !s.lifted_at(t)),
            (None, ToolInput::Hand { pose, engaged }) if cmd.tracked => (Some(pose), engaged),
            _ => (None, false),
        };
        if let Some(p) = pose {
            r.push_engaged(self.sim_time, p, engaged)?;
        }
        Ok(())
    }

    /// The frame to draw, sharing what has not changed with `previous`.
    pub fn view(&self, previous: Option<&CutView>) -> BodyView {
        self.body.body.view(previous)
    }

    /// The recorded path as a stroke (none without two poses: a stroke needs two).
    pub fn recorded(&mut self) -> Result<Option<Stroke>> {
        match self.recorder.take() {
            Some(r) if r.len() >= 2 => Ok(Some(r.finish()?)),
            _ => Ok(None),
        }
    }

    /// The released tets and where they are, for a body that releases tets.
    pub fn cut(&self) -> Option<(usize, Option<CutBox>)> {
        let parts = self.body.body.solver_parts()?;
        Some(cut_extent(parts.body.solver()))
    }

    /// Close the body, writing its `report.json` to `report`: its summary line.
    pub fn close(self, report: &Path) -> Result<String> {
        self.body.close(Some(report))
    }
}
