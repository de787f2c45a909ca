//! The simulation thread of a headset session for a scene of any method: it opens the
//! scene's body itself, steps it up to the display's newest target time with the newest
//! tool, and publishes every completed frame (its tet view and tool force) for the display
//! to draw. The display never waits for it; when the body is slower than real time it
//! falls behind and the display does not. Its failure or panic ends the session with the
//! error; the report is written by the thread when the session ends.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use incise_sim::contact::ToolPose;

use super::latest::Latest;
use super::sim_state::CommandStamp;
use crate::scene::Method;
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{TetView, ToolInput};

/// How long the thread sleeps when it has caught up with the display.
const IDLE: Duration = Duration::from_millis(1);

/// What the display asks for: the tool, and the simulated time to step up to, s.
#[derive(Debug, Clone, Copy)]
pub struct MethodCommand {
    /// The tool this frame.
    pub tool: ToolInput,
    /// Step while the body is more than half a frame behind this time.
    pub until: f64,
    /// The display frame that sampled the tool, and its predicted display time, s.
    pub stamp: CommandStamp,
}

/// A completed simulation frame, as the display draws it.
pub struct MethodState {
    /// The body as tets, with its heat-map quantity.
    pub view: TetView,
    /// Magnitude of the tissue's force on the tool, N.
    pub force: f32,
    /// Where the body draws its scalpel.
    pub scalpel: Option<ToolPose>,
    /// Frames stepped so far.
    pub frames: usize,
    /// Wall time of the frame's step, ms (0 before the first).
    pub step_ms: f64,
    /// The newest command the body was stepped with (`None`: not stepped yet).
    pub command: Option<CommandStamp>,
}

#[derive(Default)]
struct Link {
    commands: Latest<MethodCommand>,
    states: Latest<MethodState>,
    /// The body's method and where it runs, once open.
    body: OnceLock<(Method, String)>,
    stop: AtomicBool,
}

/// The running thread.
pub struct MethodThread {
    link: Arc<Link>,
    handle: Option<JoinHandle<Result<String>>>,
}

impl MethodThread {
    /// Open `scene`'s body on a new thread, each frame slowed by `slow` (testing aid); it
    /// writes its report to `report` when the session ends. Returns once the body is open,
    /// with its first state.
    pub fn spawn(scene: &Path, report: PathBuf, slow: Duration) -> Result<MethodThread> {
        let link = Arc::new(Link::default());
        let (l, scene) = (Arc::clone(&link), scene.to_path_buf());
        let handle = std::thread::spawn(move || {
            catch_unwind(AssertUnwindSafe(|| run(&scene, &report, slow, &l)))
                .unwrap_or_else(|_| Err(anyhow!("the simulation thread panicked")))
        });
        let mut t = MethodThread {
            link,
            handle: Some(handle),
        };
        while t.link.states.get().is_none() {
            if t.handle.as_ref().is_some_and(|h| h.is_finished()) {
                return Err(t
                    .join()
                    .err()
                    .unwrap_or_else(|| anyhow!("the body did not open")));
            }
            std::thread::sleep(IDLE);
        }
        Ok(t)
    }

    /// Ask for `cmd` (the newest command replaces any not yet taken).
    pub fn post(&self, cmd: MethodCommand) {
        self.link.commands.put(cmd);
    }

    /// The newest completed frame; the thread's error once it has stopped on one.
    pub fn latest(&mut self) -> Result<Arc<MethodState>> {
        if self.handle.as_ref().is_some_and(|h| h.is_finished()) {
            self.join()?;
            return Err(anyhow!("the simulation thread stopped"));
        }
        self.link
            .states
            .get()
            .ok_or_else(|| anyhow!("the simulation thread published no frame"))
    }

    /// Stop the thread; the report's summary line (the report written) and the frames
    /// the body stepped.
    pub fn finish(mut self) -> Result<(String, usize)> {
        self.link.stop.store(true, Ordering::Release);
        let summary = self.join()?;
        Ok((summary, self.frames()))
    }

    /// The body's method and where it runs ([`crate::sim_body::SimBody::device`]), named
    /// by the thread before its first frame.
    pub fn body(&self) -> Result<(Method, String)> {
        self.link
            .body
            .get()
            .cloned()
            .ok_or_else(|| anyhow!("the simulation thread has not opened its body"))
    }

    /// Frames the body has stepped so far (as published).
    pub fn frames(&self) -> usize {
        self.link.states.get().map_or(0, |s| s.frames)
    }

    fn join(&mut self) -> Result<String> {
        let h = self
            .handle
            .take()
            .ok_or_else(|| anyhow!("the simulation thread has already ended"))?;
        h.join()
            .unwrap_or_else(|_| Err(anyhow!("the simulation thread panicked")))
    }
}

impl Drop for MethodThread {
    /// A session that ends on an error still stops the thread.
    fn drop(&mut self) {
        self.link.stop.store(true, Ordering::Release);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// The thread: open, publish, then step to each command's time until stopped.
fn run(scene: &Path, report: &Path, slow: Duration, link: &Link) -> Result<String> {
    let mut sim = RecordedBody::open(scene)?;
    let _ = link.body.set((sim.body.method(), sim.body.device()));
    publish(&sim, link, 0.0, None);
    let dt = sim.body.frame_dt();
    while !link.stop.load(Ordering::Acquire) {
        let behind = link
            .commands
            .get()
            .filter(|c| sim.body.time() + 0.5 * dt < c.until);
        let Some(cmd) = behind else {
            std::thread::sleep(IDLE);
            continue;
        };
        let t0 = Instant::now();
        sim.step(&cmd.tool).map_err(anyhow::Error::msg)?;
        let step_ms = t0.elapsed().as_secs_f64() * 1e3;
        std::thread::sleep(slow);
        publish(&sim, link, step_ms, Some(cmd.stamp));
    }
    sim.close(Some(report))
}

/// Publish the body's current frame, stepped in `step_ms` with `command`.
fn publish(sim: &RecordedBody, link: &Link, step_ms: f64, command: Option<CommandStamp>) {
    link.states.put(MethodState {
        view: sim.body.tet_view(),
        force: sim.body.tool_force().map_or(0.0, |f| f.length()),
        scalpel: sim.body.scalpel_pose(),
        frames: sim.frames(),
        step_ms,
        command,
    });
}
