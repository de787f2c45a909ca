//! The simulation stepped inside each display frame (`--sim in-frame`, and exercise
//! sessions): the frame pacer's frames for the frame's predicted display time, substeps
//! cut before time when late, all before the frame renders (the display waits for them).

use std::time::Instant;

use anyhow::Result;
use incise_sim::skin::Skin;
use incise_xr::RenderDevice;
use incise_xr::openxr::HeadsetFrame;
use incise_xr::openxr::pacing::{FramePacer, PacingConfig};

use super::exercise::XrExercise;
use super::sim_state::{Advanced, ToolCommand};
use super::sim_step::{SimStepper, Stepped};
use super::xr_body::XrBody;
use crate::exercise::ToolFrame;

/// Fraction of a display period the simulation may use.
pub const SIM_BUDGET: f64 = 0.5;
/// Most simulation frames stepped in one display frame.
pub const MAX_SIM_FRAMES: u32 = 3;

/// The in-frame simulation.
pub struct InFrameSim<'s, 'x> {
    /// The body.
    pub xr: &'x mut XrBody,
    /// The frame stepper.
    pub stepper: SimStepper<'s>,
    pacer: FramePacer,
    /// Fewest substeps used.
    pub min_substeps: u32,
    pinned: Vec<u32>,
}

impl<'s, 'x> InFrameSim<'s, 'x> {
    /// Step `xr` with `stepper`; `nominal_pacing` keeps the scene's substeps.
    pub fn new(xr: &'x mut XrBody, stepper: SimStepper<'s>, nominal_pacing: bool) -> Self {
        let nominal = xr.nominal_substeps();
        let pacer = FramePacer::new(PacingConfig {
            sim_dt: xr.solver().params().frame_dt as f64,
            nominal_substeps: nominal,
            min_substeps: if nominal_pacing {
                nominal
            } else {
                xr.min_substeps()
            },
            budget_fraction: SIM_BUDGET,
            max_sim_frames: MAX_SIM_FRAMES,
        });
        InFrameSim {
            xr,
            stepper,
            pacer,
            min_substeps: nominal,
            pinned: Vec::new(),
        }
    }

    /// Simulated time given up, s.
    pub fn dropped_time(&self) -> f64 {
        self.pacer.dropped_time()
    }

    /// The pacer's frames for `frame` with `cmd`; a failed solver frame saves the
    /// exercise attempt and restarts the scene.
    pub fn advance(
        &mut self,
        frame: &HeadsetFrame,
        cmd: &ToolCommand,
        mut exercise: Option<&mut XrExercise>,
        skin: &Skin,
        dev: &RenderDevice,
    ) -> Result<Advanced> {
        let mut plan = self.pacer.plan(frame.display_time, frame.display_period);
        if cmd.paused || self.stepper.stroke_done() {
            plan.sim_frames = 0;
        }
        if plan.substeps != self.xr.solver().params().substeps {
            self.xr.set_substeps(plan.substeps)?;
        }
        let started = Instant::now();
        let mut done = Advanced {
            substeps: plan.substeps,
            ..Advanced::default()
        };
        let dt = self.xr.solver().params().frame_dt as f64;
        for _ in 0..plan.sim_frames {
            if self.stepper.stroke_done() {
                break;
            }
            match self.stepper.step(self.xr, cmd)? {
                Stepped::Done {
                    stats,
                    pose,
                    engaged,
                } => {
                    done.sim_frames += 1;
                    done.tool_force = done.tool_force.max(stats.tool_force.length());
                    if let Some(ex) = exercise.as_deref_mut() {
                        ex.after_step(ToolFrame::of_xpbd(&stats), pose, engaged, dt)?;
                    }
                }
                Stepped::Failed(e) => {
                    // The solver gave up (a tet inverted too long): the frame is rolled
                    // back; start the scene again rather than end the trainee's session.
                    eprintln!("xr: {e:#}; resetting the scene");
                    // An attempt the blade touched is scored and saved as it stood.
                    if let Some(ex) = exercise.as_deref_mut() {
                        ex.on_solver_failure(&self.xr.body, &format!("{e:#}"))?;
                    }
                    restart(self.xr, exercise, skin, dev)?;
                    break;
                }
            }
        }
        done.sim_ms = started.elapsed().as_secs_f64() * 1e3;
        if plan.sim_frames > 0 {
            self.pacer.record(plan, done.sim_ms * 1e-3);
            self.min_substeps = self.min_substeps.min(plan.substeps);
        }
        Ok(done)
    }

    /// A pressed: in an exercise, first finish an attempt the blade has touched (its card
    /// appears); otherwise start the scene over.
    pub fn on_a(
        &mut self,
        mut exercise: Option<&mut XrExercise>,
        skin: &Skin,
        dev: &RenderDevice,
    ) -> Result<()> {
        let reset = match exercise.as_deref_mut() {
            Some(ex) => ex.on_a(&self.xr.body)?,
            None => true,
        };
        if reset {
            restart(self.xr, exercise, skin, dev)?;
        }
        Ok(())
    }

    /// The body to render now and its pinned nodes.
    pub fn render_state(&mut self) -> (&XrBody, &[u32]) {
        self.pinned = incise_xr::frame::pinned_nodes(self.xr.solver());
        (self.xr, &self.pinned)
    }
}

/// The scene back to rest, and a new exercise attempt on it.
pub fn restart(
    xr: &mut XrBody,
    exercise: Option<&mut XrExercise>,
    skin: &Skin,
    dev: &RenderDevice,
) -> Result<()> {
    xr.reset()?;
    if let Some(ex) = exercise {
        ex.start(xr, skin, dev)?;
    }
    Ok(())
}
