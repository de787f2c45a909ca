//! The interface every simulation method's body implements: advance one frame with the
//! tool, the surface to draw with the method's own heat-map quantity, the tool force for
//! haptics, per-frame statistics for the report, VTU snapshots, guards and rollback.
//! `incise run`'s one frame loop (`crate::run`) drives any body through it.

use std::path::Path;

use super::body_view::{BodyView, CutView, Quantity, Substeps, TetView};
use super::outcome::Outcome;
use super::rest_cut::RestCut;
use super::tunables::Tunables;
use super::xpbd_device::{Body, DeviceChoice};
use crate::report::{FrameData, Report};
use crate::scene::Method;
use glam::Vec3;
use incise_sim::contact::ToolPose;

/// What an XPBD body's pictures draw: its solver on its device, skin and scalpel.
pub struct SolverParts<'a> {
    /// The solver on its device.
    pub body: &'a Body,
    /// The skin embedded in the tets.
    pub skin: &'a incise_sim::skin::Skin,
    /// The scene's or the hand's scalpel, when the body has one.
    pub tool: Option<&'a incise_scalpel::Tool>,
}

/// What moves the tool in the frame being stepped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolInput {
    /// The body's own script: the scene's stroke (XPBD), blade stroke (Nakao) or
    /// indenter schedule (rheology).
    Script,
    /// A hand (mouse, controller, recorded stroke) has the tool at `pose` by the end of
    /// the frame; `engaged`: the trigger or button that makes it cut, grab or press.
    Hand {
        /// Tool pose at the end of the frame.
        pose: ToolPose,
        /// Whether the tool acts (cuts, grabs, presses).
        engaged: bool,
    },
}

/// The surface of a body as it is to be drawn.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Surface {
    /// Vertex positions (the body's nodes), m.
    pub positions: Vec<Vec3>,
    /// Surface triangles of the uncut skin (outward wound, vertex indices).
    pub triangles: Vec<[u32; 3]>,
    /// Triangles of the cut surface (outward wound, vertex indices).
    pub cut_triangles: Vec<[u32; 3]>,
    /// The heat-map quantity per vertex (in [`Surface::quantity`]'s unit).
    pub scalar: Vec<f32>,
    /// What [`Surface::scalar`] is.
    pub quantity: Option<Quantity>,
}

/// Why a frame could not be stepped; the body is left at its last completed frame.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The GPU device was lost; [`SimBody::into_cpu`] continues the run on the CPU.
    #[error("{0}")]
    DeviceLost(String),
    /// The solver failed (non-finite state, inverted tets, divergence).
    #[error("{0}")]
    Failed(String),
}

/// A fault a test injects before a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// A NaN velocity on the first free node: the next frame must fail and roll back.
    Nan,
    /// The GPU device is lost.
    DeviceLoss,
}

/// How a scene's body is opened (the run's, preview's or headset's choices).
#[derive(Debug, Clone, Default)]
pub struct OpenOptions {
    /// Solver threads (default: the scene's, 0 = all cores); XPBD only.
    pub threads: Option<usize>,
    /// Where the XPBD solver runs.
    pub device: crate::sim_body::xpbd_device::DeviceChoice,
    /// An open GPU context to put an XPBD solver on when `device` asks for the GPU (a
    /// soak keeps one across its resets); `None`: one is opened for the body.
    pub gpu: Option<incise_sim::gpu::GpuContext>,
    /// Drive the scene's tool with this stroke file instead of the scene's stroke (XPBD).
    pub stroke: Option<std::path::PathBuf>,
    /// Run a Nakao scene's local loop on its own thread at this rate, Hz (PHYSICS.md §2.6).
    pub haptic_rate: Option<f64>,
    /// Replay a Nakao run's localisation: the free nodes of each localised frame of a
    /// recorded run, in order, in place of the refresh-rate manager's (or the level's)
    /// choices, so that a budgeted scene replays bit for bit (docs/reliability.md, Soak;
    /// the frame-by-frame body: a `haptic_rate` thread chooses its own).
    pub free_nodes: Option<Vec<usize>>,
    /// Run an XPBD-method scene on this time integrator instead of its `solver.scheme`
    /// (the benchmark's headset rows); `None`: the scene's own.
    pub scheme: Option<incise_sim::implicit::Scheme>,
    /// Print no notices.
    pub quiet: bool,
    /// A hand holds the tool from the start (the headset's controller): an XPBD scene's
    /// stroke is not played; its scalpel (the scene's, else the built-in one) waits above
    /// the organ, dulled, until the hand takes it (XPBD).
    pub hand: bool,
    /// With `hand`: the scene's stroke still moves the tool until the hand takes it (the
    /// preview's mouse), as a Nakao blade's or a rheology indenter's script does (XPBD).
    pub script_until_taken: bool,
}

/// A simulated body of one method, stepped frame by frame.
pub trait SimBody: Send {
    /// Which method this body runs.
    fn method(&self) -> Method;

    /// The frame length, s.
    fn frame_dt(&self) -> f64;

    /// Simulated time at the end of the last completed frame, s.
    fn time(&self) -> f64;

    /// Advance one frame with the tool as `tool` says; the frame's statistics. On an
    /// error the body stays at its last completed frame (guarded and rolled back).
    fn step(&mut self, tool: &ToolInput) -> Result<FrameData, StepError>;

    /// Do now the part of the next frame that does not depend on the tool's pose (the
    /// implicit scheme's coarse refactorisation after releases, `Solver::prepare_frame`):
    /// a caller that reads the pose just before each frame calls this after showing the
    /// last one, so the frame's step starts sooner after its pose. The next frame does it
    /// itself otherwise, to the same bits.
    fn prepare_next_frame(&mut self) {}

    /// Where the tool is at the end of the last frame (`None`: no tool).
    fn tool_pose(&self) -> Option<ToolPose>;

    /// Where a scalpel is drawn for the body's tool at the end of the last frame: the
    /// pose its hand, stroke file or script gave the blade, turned as a hand holds a
    /// scalpel (`None`: no blade, or the method's tool is no scalpel, e.g. an indenter).
    fn scalpel_pose(&self) -> Option<ToolPose> {
        None
    }

    /// Force of the tissue on the tool in the last frame, N (`None`: no tool).
    fn tool_force(&self) -> Option<Vec3>;

    /// The surface to draw, with the method's heat-map quantity per vertex.
    fn surface(&self) -> Surface;

    /// The body as tets for the renderer, with the heat-map quantity per tet.
    fn tet_view(&self) -> TetView;

    /// Write the body's state as a `.vtu` file at `path`.
    fn write_vtu(&self, path: &Path) -> anyhow::Result<()>;

    /// The figures the progress line shows for `frame` (the method's own).
    fn progress_line(&self, frame: &FrameData) -> String;

    /// Where the body runs: "cpu", the GPU adapter, or the method's CPU loop.
    fn device(&self) -> String;

    /// GPU kernel time of the last frame, ms, where the body runs on a GPU with timestamps.
    fn gpu_frame_ms(&self) -> Option<f64> {
        None
    }

    /// After [`StepError::DeviceLost`]: the body on the CPU from its last completed frame
    /// (a body that runs on the CPU already stays as it is).
    fn into_cpu(self: Box<Self>) -> Box<dyn SimBody>;

    /// The body's result now, in its method's terms, for checking that a replay or a
    /// rollback reproduces it bit for bit (`None`: a haptic thread holds the state).
    fn outcome(&self) -> Option<Outcome>;

    /// What the body has cut, in rest coordinates, for scoring an exercise (`None`: the
    /// method does not cut, or a haptic thread holds the state).
    fn rest_cut(&self) -> Option<RestCut> {
        None
    }

    /// Inject `fault` (testing aid); an error when the method has no such fault.
    fn inject(&mut self, fault: Fault) -> anyhow::Result<()>;

    /// Whether the body's state is on this thread between frames, so that a snapshot can
    /// be written (false: a haptic thread holds it until the run ends).
    fn holds_state(&self) -> bool {
        true
    }

    /// Fill the report's end-of-run figures (counts after cutting, released tets, the
    /// method's own sections); called once, after the last frame. Returns the line the
    /// run prints at its end, where the method has one.
    fn finish(&mut self, report: &mut Report) -> anyhow::Result<Option<String>>;

    /// The XPBD solver's parts that its own pictures draw (the solver on its device, the
    /// skin, the scalpel); `None` for a body drawn from its [`SimBody::tet_view`].
    fn solver_parts(&self) -> Option<SolverParts<'_>> {
        None
    }

    /// The frame to draw, sharing with `previous` (a frame of this body drawn before)
    /// what has not changed.
    fn view(&self, _previous: Option<&CutView>) -> BodyView {
        BodyView::Tets(self.tet_view())
    }

    /// The substeps of a body whose solver may run fewer to keep real time (`None`: the
    /// method steps a frame its own way).
    fn substeps(&self) -> Option<Substeps> {
        None
    }

    /// Run `n` substeps a frame from now on, continuing the motion, cut and grabs; an
    /// error for a body without [`SimBody::substeps`].
    fn set_substeps(&mut self, n: u32) -> anyhow::Result<()> {
        anyhow::bail!(
            "a {} body has no substeps to set to {n}",
            self.method().name()
        )
    }

    /// Put the tool where a hand takes it, `pose`, at the current frame without stepping
    /// (`engaged`: cutting, else held dulled), so that the next frame's motion starts
    /// there, as a recorded stroke's first pose does in its replay (XPBD; other methods
    /// take the hand's pose each frame and need nothing).
    fn hold_tool(&mut self, _pose: ToolPose, _engaged: bool) -> anyhow::Result<()> {
        Ok(())
    }

    /// The settings a user may change while the body runs (`None`: the method has none).
    fn tunables(&self) -> Option<Tunables> {
        None
    }

    /// Run with `settings` from now on, on `device`, continuing the motion, cut and
    /// grabs; refused settings (unstable, out of range) leave the body as it was.
    fn retune(&mut self, settings: Tunables, device: DeviceChoice) -> anyhow::Result<()> {
        let _ = (settings, device);
        anyhow::bail!("a {} body has no settings to change", self.method().name())
    }

    /// Whether the body's own script moves its tool on [`ToolInput::Script`] (a Nakao
    /// blade's stroke, a rheology indenter, an XPBD scene's stroke), so a hand takes the
    /// tool over only when it engages; false: the tool waits for the hand.
    fn script_holds_tool(&self) -> bool {
        true
    }
}
