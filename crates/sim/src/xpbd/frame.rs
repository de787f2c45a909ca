//! Per-frame statistics reported by the solver.

use glam::Vec3;
use serde::Serialize;

/// What one frame did, for report.json.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FrameStats {
    /// Frame index (0-based).
    pub frame: u64,
    /// Simulation time at the end of the frame, s.
    pub sim_time: f64,
    /// Substeps taken.
    pub substeps: u32,
    /// Largest von Mises stress over live tets, Pa.
    pub max_von_mises: f32,
    /// Mean von Mises stress over live tets, Pa.
    pub mean_von_mises: f32,
    /// Tets released in this frame.
    pub released_now: usize,
    /// Tets released so far.
    pub released_total: usize,
    /// Nodes retired so far.
    pub retired_nodes: usize,
    /// Current volume of the live tets over their rest volume.
    pub volume_ratio: f64,
    /// Kinetic energy ½ Σ m v², J.
    pub kinetic_energy: f64,
    /// Mean force the tissue exerted on the tool this frame (x, y, z), N.
    pub tool_force: Vec3,
    /// Nodes the tool pushed during the frame.
    pub contact_nodes: usize,
    /// Wall time of the substeps (prediction, projection, velocity update, and the release
    /// checks that fall in them), ms.
    pub solve_ms: f64,
    /// Of `solve_ms`, the release checks (stress and release) inside the substeps, ms (CPU;
    /// on the GPU they run in the same submission and are not timed apart: 0).
    pub check_ms: f64,
    /// Wall time of stress, guards and release, ms.
    pub stress_ms: f64,
    /// Wall time of the frame's work done before it took the tool's pose
    /// (`Solver::prepare_frame`, as the headset calls it after showing the last frame:
    /// the implicit scheme's coarse refactorisation after the last frame's releases), ms;
    /// 0 where there was none or the frame did it itself.
    pub ahead_ms: f64,
    /// Parallel passes of the frame: on the CPU the colour and stress passes (each ends
    /// in a synchronisation of the threads), on the GPU the compute dispatches.
    pub passes: u32,
    /// Conjugate-gradient products of the frame's Newton iterations (0 under XPBD).
    pub cg_products: u32,
    /// Newton iterations of the frame's implicit steps (0 under XPBD).
    pub newton_iterations: u32,
    /// Of those, the iterations whose conjugate gradient stopped at non-positive
    /// curvature (a torn organ's indefinite tangent).
    pub negative_curvature: u32,
    /// Step halvings of the Newton line searches (0 under XPBD).
    pub line_search_halvings: u32,
    /// Implicit steps of the frame that re-assembled the coarse matrix (0 under XPBD).
    pub coarse_refreshes: u32,
    /// Times the frame was run again at twice the implicit steps because it left more
    /// live tets inverted than it found (a tool attached; 0 under XPBD).
    pub split_frames: u32,
    /// Coarse nodes of the implicit scheme's preconditioner at the frame's end (0 under
    /// XPBD): more than the whole body's once a cut has split the grid.
    pub coarse_nodes: u32,
}
