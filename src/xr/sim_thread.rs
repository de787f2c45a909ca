//! The simulation thread: it owns the body for the session, steps fixed-dt frames paced
//! to real time by the frame pacer (substeps cut first, then simulated time given up when
//! a frame costs more than its dt), each with the display's newest tool command, and
//! publishes every completed frame for the display to render. The display never waits
//! for it; when it is slower than real time it falls behind, the display does not.
//! Its errors and panics end the session with the error, the stroke still saved.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use incise_scalpel::Stroke;
use incise_xr::openxr::pacing::{FramePacer, PacingConfig};

use super::latest::Latest;
use super::sim_state::{SimState, ToolCommand};
use super::sim_step::{SimStepper, Stepped};
use super::xr_body::XrBody;

/// Fraction of a simulation frame's dt its step may take on the thread before substeps
/// are cut (the rest is headroom to catch up).
pub const THREAD_BUDGET: f64 = 0.9;
/// Most simulation frames stepped at once after the thread fell behind; the rest of the
/// owed time is given up.
pub const MAX_CATCH_UP: u32 = 3;

/// What the display and the simulation thread share.
#[derive(Default)]
pub struct SimLink {
    /// The display's newest command.
    pub commands: Latest<ToolCommand>,
    /// The newest completed simulation frame.
    pub states: Latest<SimState>,
    stop: AtomicBool,
    failure: Mutex<Option<anyhow::Error>>,
}

impl SimLink {
    /// Ask the thread to stop (it finishes the frame it is stepping).
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Release);
    }

    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Acquire)
    }

    /// The error that stopped the thread, once (then `None`).
    pub fn take_failure(&self) -> Option<anyhow::Error> {
        self.failure
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take()
    }

    fn fail(&self, e: anyhow::Error) {
        *self
            .failure
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(e);
    }
}

/// How the thread runs.
pub struct ThreadConfig {
    /// Keep the scene's substeps whatever the cost (a played stroke).
    pub nominal_pacing: bool,
}

/// What the thread did, returned when it ends.
pub struct ThreadOutcome {
    /// Frames stepped.
    pub frames: u64,
    /// Simulated time given up, s.
    pub dropped_time: f64,
    /// Fewest substeps used.
    pub min_substeps_used: u32,
    /// Times the solver failed and the scene was reset.
    pub solver_resets: u32,
    /// Largest contact force, N.
    pub max_force: f32,
    /// The scalpel's recorded path.
    pub stroke: Option<Stroke>,
    /// Wall time from the first command to the end, s.
    pub wall_s: f64,
}

/// The thread's state.
struct SimLoop<'s, 'x> {
    xr: &'x mut XrBody,
    link: &'s SimLink,
    stepper: SimStepper<'s>,
    pacer: FramePacer,
    resets_seen: u64,
    min_substeps: u32,
    sim_dt: f64,
    started: Option<Instant>,
}

/// Run the simulation of `xr` until `link` says stop; `stepper` steps the frames.
pub fn run(
    xr: &mut XrBody,
    link: &SimLink,
    stepper: SimStepper<'_>,
    cfg: ThreadConfig,
) -> ThreadOutcome {
    let nominal = xr.nominal_substeps();
    let sim_dt = xr.solver().params().frame_dt as f64;
    let min = if cfg.nominal_pacing {
        nominal
    } else {
        xr.min_substeps()
    };
    let pacer = FramePacer::new(PacingConfig {
        sim_dt,
        nominal_substeps: nominal,
        min_substeps: min,
        budget_fraction: THREAD_BUDGET,
        max_sim_frames: MAX_CATCH_UP,
    });
    let mut sim = SimLoop {
        xr,
        link,
        stepper,
        pacer,
        resets_seen: 0,
        min_substeps: nominal,
        sim_dt,
        started: None,
    };
    // A panic is caught here so the path recorded so far survives it.
    let ended = catch_unwind(AssertUnwindSafe(|| sim.run())).unwrap_or_else(|p| {
        Err(anyhow!(
            "the simulation thread panicked: {}",
            panic_text(p.as_ref())
        ))
    });
    let stroke = match sim.stepper.recorded() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("xr: the recorded stroke: {e:#}");
            None
        }
    };
    if let Err(e) = ended {
        link.fail(e);
    }
    ThreadOutcome {
        frames: sim.stepper.frames,
        dropped_time: sim.pacer.dropped_time(),
        min_substeps_used: sim.min_substeps,
        solver_resets: sim.stepper.failures,
        max_force: sim.stepper.max_force,
        stroke,
        wall_s: sim.started.map_or(0.0, |t| t.elapsed().as_secs_f64()),
    }
}

/// The message of a caught panic.
fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

impl SimLoop<'_, '_> {
    fn run(&mut self) -> Result<()> {
        self.stepper.start(self.xr)?;
        // The clock starts with the display's first command.
        while self.link.commands.get().is_none() {
            if self.link.stopped() {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let clock = Instant::now();
        self.started = Some(clock);
        self.publish(true, 0.0);
        while !self.link.stopped() {
            let cmd = self.command();
            let rebuilt = self.apply_reset(&cmd)?;
            let mut plan = self.pacer.plan(clock.elapsed().as_secs_f64(), self.sim_dt);
            if cmd.paused || self.stepper.stroke_done() {
                plan.sim_frames = 0;
            }
            if plan.sim_frames == 0 {
                if rebuilt {
                    self.publish(true, 0.0);
                }
                self.sleep_until_owed();
                continue;
            }
            let started = Instant::now();
            self.step_frames(plan.sim_frames, plan.substeps, rebuilt)?;
            self.pacer.record(plan, started.elapsed().as_secs_f64());
            self.min_substeps = self.min_substeps.min(plan.substeps);
        }
        Ok(())
    }

    fn command(&self) -> ToolCommand {
        *self
            .link
            .commands
            .get()
            .expect("the loop starts after the first command")
    }

    /// A reset the display asked for since the last frame: the scene back to rest.
    fn apply_reset(&mut self, cmd: &ToolCommand) -> Result<bool> {
        if cmd.resets <= self.resets_seen {
            return Ok(false);
        }
        self.resets_seen = cmd.resets;
        self.xr.reset()?;
        Ok(true)
    }

    /// `frames` frames at `substeps`, each with the newest command, each published
    /// (`rebuilt`: the scene was rebuilt since the last one published).
    fn step_frames(&mut self, frames: u32, substeps: u32, mut rebuilt: bool) -> Result<()> {
        if substeps != self.xr.solver().params().substeps {
            self.xr.set_substeps(substeps)?;
            rebuilt = true;
        }
        for _ in 0..frames {
            let cmd = self.command();
            match self.stepper.step(self.xr, &cmd)? {
                Stepped::Done { stats, .. } => {
                    self.publish(rebuilt, stats.tool_force.length());
                    rebuilt = false;
                }
                Stepped::Failed(e) => {
                    // Rolled back: start the scene again rather than end the session.
                    eprintln!("xr: {e:#}; resetting the scene");
                    self.xr.reset()?;
                    self.publish(true, 0.0);
                    break;
                }
            }
            if self.stepper.stroke_done() {
                break;
            }
        }
        Ok(())
    }

    fn publish(&self, rebuilt: bool, tool_force: f32) {
        let previous = self.link.states.get();
        let mut s = SimState::capture(self.xr, previous.as_deref(), rebuilt);
        s.frame = self.stepper.frames;
        s.sim_time = self.stepper.sim_time;
        s.tool_force = tool_force;
        s.step_ms = self.stepper.last_ms;
        s.command = self.stepper.last_command;
        s.stroke_done = self.stepper.stroke_done();
        self.link.states.put(s);
    }

    fn sleep_until_owed(&self) {
        let wait = self.pacer.until_next_frame().clamp(0.0005, self.sim_dt);
        std::thread::sleep(Duration::from_secs_f64(wait));
    }
}
