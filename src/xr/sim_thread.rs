//! The simulation thread of a headset session, for a body of any method: it owns the
//! body ([`LiveSim`]) for the session, steps fixed-dt frames paced to real time by the
//! frame pacer (substeps cut first where the body has them, then simulated time given up
//! when a frame costs more than its dt), each with the display's newest command, and
//! publishes every completed frame for the display to draw. A frame starts when a
//! display frame's new pose arrives, if it falls due within a frame, rather than on the
//! thread's own clock ([`FramePacer::plan_on_thread`]): a step shorter than the display
//! period then shows its pose's effect at the next display frame; behind, it waits for
//! the next pose where its step would show at the same display frame either way
//! ([`wait_for_next_pose`]). The display never waits for it; when it is slower than real
//! time it falls behind, the display does not. Its errors and panics end the session
//! with the error; the body comes back to the session however it ended (its recorded
//! stroke and report are still saved).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::pacing::{FramePacer, wait_for_next_pose};
use anyhow::{Result, anyhow};
use incise_sim::contact::ToolPose;

use super::command::{BodyCommand, CommandStamp};
use super::latest::Latest;
use super::live_sim::{LiveSim, Stepped};
use crate::sim_body::BodyView;

/// Fraction of a simulation frame's dt its step may take on the thread before substeps
/// are cut (the rest is headroom to catch up).
pub const THREAD_BUDGET: f64 = 0.9;
/// Most simulation frames stepped at once after the thread fell behind (or in one display
/// frame); the rest of the owed time is given up.
pub const MAX_CATCH_UP: u32 = 3;

/// A completed simulation frame, as the display draws it.
pub struct Published {
    /// The body.
    pub view: BodyView,
    /// Magnitude of the tissue's force on the tool, N.
    pub force: f32,
    /// Where the body draws its scalpel.
    pub scalpel: Option<ToolPose>,
    /// Simulation frames stepped in the session so far.
    pub frames: u64,
    /// Substeps the frame ran.
    pub substeps: u32,
    /// Wall time of the frame's step, ms (0 before the first).
    pub step_ms: f64,
    /// The newest command the frame was stepped with (`None`: not stepped yet).
    pub command: Option<CommandStamp>,
    /// A played stroke has been played to its end.
    pub stroke_done: bool,
}

impl Published {
    /// The state of `live` now, sharing its cut with `previous` where unchanged.
    fn of(live: &LiveSim, previous: Option<&Published>) -> Published {
        let shared = previous.and_then(|p| match &p.view {
            BodyView::Cut(c) => Some(c),
            BodyView::Tets(_) => None,
        });
        Published {
            view: live.view(shared),
            force: live.force,
            scalpel: live.body.body.scalpel_pose(),
            frames: live.frames,
            substeps: live.substeps(),
            step_ms: live.last_ms,
            command: live.last_command,
            stroke_done: live.stroke_done(),
        }
    }
}

/// What the display and the thread share.
#[derive(Default)]
struct Link {
    commands: Latest<BodyCommand>,
    states: Latest<Published>,
    stop: AtomicBool,
    failure: Mutex<Option<anyhow::Error>>,
}

impl Link {
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Acquire)
    }

    fn fail(&self, e: anyhow::Error) {
        *self.failure.lock().unwrap_or_else(PoisonError::into_inner) = Some(e);
    }

    fn take_failure(&self) -> Option<anyhow::Error> {
        self.failure
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
    }
}

/// What the thread did, returned when it ends.
pub struct ThreadEnd {
    /// The body, as the thread left it.
    pub live: LiveSim,
    /// Simulated time given up, s.
    pub dropped_time: f64,
    /// Wall time from the first command to the end, s.
    pub wall_s: f64,
    /// The failure that stopped the thread, if the display has not taken it.
    pub error: Option<anyhow::Error>,
}

/// The running thread.
pub struct SimThread {
    link: Arc<Link>,
    handle: Option<JoinHandle<ThreadEnd>>,
}

impl SimThread {
    /// Step `live` on a new thread, paced to real time (the scene's substeps kept when
    /// `nominal`); its first state is published at once.
    pub fn spawn(live: LiveSim, nominal: bool) -> Result<SimThread> {
        let link = Arc::new(Link::default());
        link.states.put(Published::of(&live, None));
        let l = Arc::clone(&link);
        let handle = std::thread::Builder::new()
            .name("incise-sim".into())
            .spawn(move || run(live, nominal, &l))?;
        Ok(SimThread {
            link,
            handle: Some(handle),
        })
    }

    /// Ask for `cmd` (the newest command replaces any not yet taken).
    pub fn post(&self, cmd: BodyCommand) {
        self.link.commands.put(cmd);
    }

    /// The newest completed frame; the thread's error once it has stopped on one.
    pub fn latest(&self) -> Result<Arc<Published>> {
        if let Some(e) = self.link.take_failure() {
            return Err(e);
        }
        self.link
            .states
            .get()
            .ok_or_else(|| anyhow!("the simulation thread published no frame"))
    }

    /// Stop the thread (it finishes the frame it is stepping) and take the body back.
    pub fn finish(mut self) -> Result<ThreadEnd> {
        self.link.stop.store(true, Ordering::Release);
        let h = self
            .handle
            .take()
            .ok_or_else(|| anyhow!("the simulation thread has already ended"))?;
        let mut end = h
            .join()
            .map_err(|_| anyhow!("the simulation thread panicked while saving its outcome"))?;
        end.error = end.error.or_else(|| self.link.take_failure());
        Ok(end)
    }
}

impl Drop for SimThread {
    /// A session that ends on an error still stops the thread.
    fn drop(&mut self) {
        self.link.stop.store(true, Ordering::Release);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// The thread: step until stopped; a panic is caught so the body comes back.
fn run(mut live: LiveSim, nominal: bool, link: &Link) -> ThreadEnd {
    let pacer = live.pacer(THREAD_BUDGET, MAX_CATCH_UP, nominal);
    let mut sim = Loop {
        link,
        pacer,
        resets_seen: 0,
        started: None,
        period: None,
    };
    let ended = catch_unwind(AssertUnwindSafe(|| sim.run(&mut live))).unwrap_or_else(|p| {
        Err(anyhow!(
            "the simulation thread panicked: {}",
            panic_text(p.as_ref())
        ))
    });
    if let Err(e) = ended {
        link.fail(e);
    }
    ThreadEnd {
        dropped_time: sim.pacer.dropped_time(),
        wall_s: sim.started.map_or(0.0, |t| t.elapsed().as_secs_f64()),
        live,
        error: None,
    }
}

/// The message of a caught panic.
fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

/// The thread's pacing state.
struct Loop<'l> {
    link: &'l Link,
    pacer: FramePacer,
    resets_seen: u64,
    started: Option<Instant>,
    /// The display period, s, from the stamps of the poses stepped with.
    period: Option<f64>,
}

impl Loop<'_> {
    fn run(&mut self, live: &mut LiveSim) -> Result<()> {
        // The clock starts with the display's first command.
        while self.link.commands.get().is_none() {
            if self.link.stopped() {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let clock = Instant::now();
        self.started = Some(clock);
        let dt = live.dt();
        while !self.link.stopped() {
            let cmd = self.command();
            if cmd.resets > self.resets_seen {
                self.resets_seen = cmd.resets;
                live.reset()?;
                self.publish(live);
            }
            if cmd.paused || live.stroke_done() {
                self.pacer.plan(clock.elapsed().as_secs_f64(), dt);
                self.sleep(self.pacer.until_next_frame(), dt);
                continue;
            }
            let fresh = live.last_command.map(|(frame, _)| frame) != Some(cmd.stamp.0);
            let plan = self
                .pacer
                .plan_on_thread(clock.elapsed().as_secs_f64(), fresh);
            if plan.sim_frames == 0 {
                self.wait(&cmd, fresh, dt);
                continue;
            }
            if fresh {
                self.align_with_next_pose(&cmd, live.last_command, live.last_ms * 1e-3);
            }
            let started = Instant::now();
            live.set_substeps(plan.substeps)?;
            self.step_frames(live, plan.sim_frames)?;
            self.pacer.record(plan, started.elapsed().as_secs_f64());
        }
        Ok(())
    }

    /// With no frame to step: wait until one falls due or the display posts a pose from
    /// a newer display frame than `cmd`'s (`fresh`: `cmd` not stepped with yet).
    fn wait(&self, cmd: &BodyCommand, fresh: bool, dt: f64) {
        let until = self
            .pacer
            .until_due_on_thread(fresh)
            .clamp(0.0005, 2.0 * dt);
        let frame = cmd.stamp.0;
        self.link
            .commands
            .wait_for(Duration::from_secs_f64(until), |c| c.stamp.0 != frame);
    }

    /// Before a step with the pose of `cmd` (the last step, with the pose of `stepped`,
    /// took `step` s): wait for the next pose where the step would show at the same
    /// display frame either way ([`wait_for_next_pose`]); the step then takes the newer
    /// one.
    fn align_with_next_pose(
        &mut self,
        cmd: &BodyCommand,
        stepped: Option<CommandStamp>,
        step: f64,
    ) {
        let (frame, time) = cmd.stamp;
        if let Some((f0, t0)) = stepped.filter(|&(f0, _)| frame > f0) {
            self.period = Some((time - t0) / (frame - f0) as f64);
        }
        let age = self.link.commands.age().map_or(0.0, |a| a.as_secs_f64());
        let Some(period) = self.period else {
            return;
        };
        if let Some(wait) = wait_for_next_pose(age, step, period) {
            self.link
                .commands
                .wait_for(Duration::from_secs_f64(wait), |c| c.stamp.0 != frame);
        }
    }

    /// Sleep `s` seconds (at least half a millisecond, at most `dt`).
    fn sleep(&self, s: f64, dt: f64) {
        std::thread::sleep(Duration::from_secs_f64(s.clamp(0.0005, dt)));
    }

    fn command(&self) -> BodyCommand {
        *self
            .link
            .commands
            .get()
            .expect("the loop starts after the first command")
    }

    /// `frames` frames, each with the newest command, each published; a failed one
    /// starts the scene over.
    fn step_frames(&mut self, live: &mut LiveSim, frames: u32) -> Result<()> {
        for _ in 0..frames {
            let cmd = self.command();
            match live.step(&cmd)? {
                Stepped::Done => {
                    self.publish(live);
                    // The next frame's pose-free work now, before it takes its pose.
                    live.prepare_next();
                }
                Stepped::Failed(e) => {
                    // Rolled back: start the scene again rather than end the session.
                    eprintln!("xr: {e}; resetting the scene");
                    live.reset()?;
                    self.publish(live);
                    break;
                }
            }
            if live.stroke_done() {
                break;
            }
        }
        Ok(())
    }

    /// Publish `live`'s frame, sharing what is unchanged with the last one published (a
    /// reset's new body shares nothing: [`crate::sim_body::SimBody::view`]).
    fn publish(&self, live: &LiveSim) {
        let previous = self.link.states.get();
        self.link
            .states
            .put(Published::of(live, previous.as_deref()));
    }
}
