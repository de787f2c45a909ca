//! An XPBD headset session: the solver stepped in each display frame ([`InFrameSim`]) or
//! on its own thread ([`sim_thread`]: the display draws its newest completed state), as
//! the one display loop ([`super::frame_loop`]) drives it through [`HeadsetSim`].

use anyhow::{Result, bail};
use incise_scalpel::Stroke;
use incise_sim::skin::Skin;
use incise_xr::openxr::scalpel_pose::BladeOffset;
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{Headset, HeadsetFrame};
use incise_xr::{RenderDevice, Renderer};

use super::exercise::XrExercise;
use super::frame_loop::{DisplayOptions, DisplayOutcome, drive};
use super::headset_sim::{HeadsetSim, Picture};
use super::in_frame::InFrameSim;
use super::sim_mode::SimMode;
use super::sim_source::{Sim, ThreadSim};
use super::sim_state::{Advanced, CommandStamp, SimState, ToolCommand};
use super::sim_step::{SimFaults, SimStepper};
use super::sim_thread::{self, SimLink, ThreadConfig};
use super::xr_body::XrBody;

/// How the loop runs.
pub struct LoopOptions<'a> {
    /// Stop after this many display frames (asks the session to exit).
    pub max_frames: Option<u64>,
    /// Where the blade sits on the right controller.
    pub blade: BladeOffset,
    /// Contact force (N) → vibration amplitude (0..1): the scalpel's haptic curve.
    pub haptic: &'a dyn Fn(f32) -> f32,
    /// Keep the scene's substeps whatever the measured cost.
    pub nominal_pacing: bool,
    /// Record the scalpel's path as a stroke.
    pub record: bool,
    /// The tray at the start.
    pub tray: Tray,
    /// Drive the scalpel along this stroke (sim world, simulation time), engaged, instead
    /// of the right controller; the session ends when the stroke has been played.
    pub stroke: Option<&'a Stroke>,
    /// Where the solver is stepped.
    pub sim_mode: SimMode,
    /// Testing aids: a NaN before a simulation frame (rolled back, the scene reset), a
    /// panic, an artificially slow solver.
    pub faults: SimFaults,
}

/// What a session did.
pub struct LoopOutcome {
    /// What the display loop did: frames, vibration, how the session ended, the frame
    /// log.
    pub display: DisplayOutcome,
    /// Simulation frames stepped.
    pub sim_frames: u64,
    /// Released tets at the end.
    pub released_tets: usize,
    /// Bounding box (min, max corners, sim world, m) of the released tets' rest
    /// centroids: where the cut is.
    pub cut_box: Option<super::xr_body::CutBox>,
    /// Largest tool contact force, N.
    pub max_tool_force: f32,
    /// Simulated time given up to keep real time, s.
    pub dropped_time: f64,
    /// Wall time the simulation ran, s (the thread: from the first command).
    pub sim_wall_s: f64,
    /// Fewest substeps used.
    pub min_substeps_used: u32,
    /// Times the solver failed and the scene was reset.
    pub solver_resets: u32,
    /// The scalpel's path, when recorded and the controller was tracked.
    pub stroke: Option<Stroke>,
}

/// What the XPBD simulation needs besides its body to draw and to restart: the renderer
/// of its mesh, the skin and the device exercise pictures are taken on.
struct Drawn<'a> {
    renderer: &'a mut Renderer,
    skin: &'a Skin,
    dev: &'a RenderDevice,
}

/// Run the session on `headset` until it ends.
pub fn run_loop(
    headset: &mut dyn Headset,
    xr: &mut XrBody,
    skin: &Skin,
    opts: &LoopOptions<'_>,
    exercise: Option<&mut XrExercise>,
) -> Result<LoopOutcome> {
    if opts.sim_mode == SimMode::Thread && exercise.is_some() {
        bail!("exercise sessions step the solver in the frame loop (--sim in-frame)");
    }
    let dev = headset.device().clone();
    let mut renderer = Renderer::new(
        &dev.device,
        &dev.queue,
        headset.format(),
        xr.solver().mesh(),
        skin,
    );
    let drawn = Drawn {
        renderer: &mut renderer,
        skin,
        dev: &dev,
    };
    let sim_dt = xr.solver().params().frame_dt as f64;
    let stepper = SimStepper::new(opts.stroke, sim_dt, opts.record, opts.faults);
    let display = DisplayOptions {
        max_frames: opts.max_frames,
        blade: opts.blade,
        haptic: opts.haptic,
        tray: opts.tray,
        played: opts.stroke.is_some(),
    };
    let mut out = match opts.sim_mode {
        SimMode::InFrame => in_frame(headset, xr, stepper, (opts, &display), drawn, exercise),
        SimMode::Thread => threaded(headset, xr, stepper, (opts, &display), drawn)?,
    };
    (out.released_tets, out.cut_box) = xr.cut_extent();
    Ok(out)
}

/// The session with the solver stepped in each frame.
fn in_frame(
    headset: &mut dyn Headset,
    xr: &mut XrBody,
    stepper: SimStepper<'_>,
    (opts, display): (&LoopOptions<'_>, &DisplayOptions<'_>),
    drawn: Drawn<'_>,
    exercise: Option<&mut XrExercise>,
) -> LoopOutcome {
    let mut s = InFrameSim::new(xr, stepper, opts.nominal_pacing);
    let mut sim = XpbdSim {
        sim: Sim::InFrame(&mut s),
        exercise,
        drawn,
    };
    let mut shown = drive(headset, &mut sim, display);
    // Kept however the session ended.
    let stroke = match s.stepper.recorded() {
        Ok(stroke) => stroke,
        Err(e) => {
            shown.error.get_or_insert(e);
            None
        }
    };
    LoopOutcome {
        sim_frames: s.stepper.frames,
        released_tets: 0,
        cut_box: None,
        max_tool_force: s.stepper.max_force,
        dropped_time: s.dropped_time(),
        sim_wall_s: shown.wall_s,
        min_substeps_used: s.min_substeps,
        solver_resets: s.stepper.failures,
        stroke,
        display: shown,
    }
}

/// The session with the solver on its own thread.
fn threaded(
    headset: &mut dyn Headset,
    xr: &mut XrBody,
    stepper: SimStepper<'_>,
    (opts, display): (&LoopOptions<'_>, &DisplayOptions<'_>),
    drawn: Drawn<'_>,
) -> Result<LoopOutcome> {
    let link = SimLink::default();
    // A state to show before the thread's first frame.
    link.states.put(SimState::capture(xr, None, true));
    let cfg = ThreadConfig {
        nominal_pacing: opts.nominal_pacing,
    };
    let shared = &link;
    std::thread::scope(|scope| {
        let thread = std::thread::Builder::new()
            .name("incise-sim".into())
            .spawn_scoped(scope, move || sim_thread::run(xr, shared, stepper, cfg))?;
        let mut t = ThreadSim::new(shared);
        let mut sim = XpbdSim {
            sim: Sim::Thread(&mut t),
            exercise: None,
            drawn,
        };
        let mut shown = drive(headset, &mut sim, display);
        shared.stop();
        let t = match thread.join() {
            Ok(t) => t,
            // It catches its own panics; this would be one while saving its outcome.
            Err(_) => bail!("the simulation thread panicked"),
        };
        // The thread's own failure comes first: the display only saw it stop.
        if let Some(e) = shared.take_failure() {
            shown.error = Some(e);
        }
        Ok(LoopOutcome {
            display: shown,
            sim_frames: t.frames,
            released_tets: 0,
            cut_box: None,
            max_tool_force: t.max_force,
            dropped_time: t.dropped_time,
            sim_wall_s: t.wall_s,
            min_substeps_used: t.min_substeps_used,
            solver_resets: t.solver_resets,
            stroke: t.stroke,
        })
    })
}

/// The XPBD simulation as the display loop drives it.
struct XpbdSim<'a, 's, 'x, 'e> {
    sim: Sim<'a, 's, 'x>,
    exercise: Option<&'e mut XrExercise>,
    drawn: Drawn<'a>,
}

impl HeadsetSim for XpbdSim<'_, '_, '_, '_> {
    fn heat_map_at_start(&self) -> bool {
        false
    }

    fn start(&mut self) -> Result<()> {
        let d = &self.drawn;
        self.sim.start(self.exercise.as_deref_mut(), d.skin, d.dev)
    }

    fn on_a(&mut self) -> Result<()> {
        let d = &self.drawn;
        self.sim.on_a(self.exercise.as_deref_mut(), d.skin, d.dev)
    }

    fn advance(&mut self, frame: &HeadsetFrame, cmd: &ToolCommand) -> Result<Advanced> {
        let d = &self.drawn;
        let ex = self.exercise.as_deref_mut();
        self.sim.advance(frame, *cmd, ex, d.skin, d.dev)
    }

    fn picture(&mut self, tray: &Tray, head: glam::Vec3) -> Result<Option<Picture<'_>>> {
        let d = &mut self.drawn;
        // The plan on the tissue and the result card above the tray.
        let (lines, panel) = match (self.exercise.as_deref_mut(), self.sim.body()) {
            (Some(ex), Some(xr)) => {
                let panel = ex.panel(d.renderer, d.dev, tray, head)?;
                (ex.lines(xr), panel)
            }
            _ => (Vec::new(), None),
        };
        let Some(input) = self.sim.render_input() else {
            return Ok(None);
        };
        let (pose, tracked) = input.tool;
        Ok(Some(Picture {
            renderer: d.renderer,
            body: input.body,
            heat_max: input.stress_max,
            tool: tracked.then_some(pose),
            lines,
            panel,
        }))
    }

    fn shown_command(&self) -> Option<CommandStamp> {
        self.sim.shown_command()
    }

    fn stroke_done(&self) -> bool {
        self.sim.stroke_done()
    }

    fn end(&mut self) -> Result<()> {
        match (self.exercise.as_deref_mut(), self.sim.body()) {
            (Some(ex), Some(xr)) => ex.end_session(&xr.body),
            _ => Ok(()),
        }
    }
}
