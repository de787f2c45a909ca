//! XPBD small-steps solver for Neo-Hookean tets (PHYSICS.md §1.2), CPU reference.

mod coloring;
mod frame;
mod neo_hookean;
mod params;
mod shared_nodes;
mod solver;
mod stability;

pub use coloring::greedy_tet_colors;
pub use frame::FrameStats;
pub use neo_hookean::{TetProjection, TetTerms, deformation_gradient, det_gradient, project_tet};
pub use params::{SolverError, SolverParams};
pub use solver::{NodeKind, Solver};
pub use stability::{MAX_STIFFNESS_NUMBER, stiffness_number, substeps_needed};
