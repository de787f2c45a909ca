//! The implicit scheme's pieces: one implicit Euler step per (frame / `steps`), its
//! minimisation by Newton's method, each Newton system by a conjugate gradient
//! preconditioned on two levels (block Jacobi or symmetric Gauss–Seidel on the tet mesh, a
//! Cholesky-factorised Galerkin coarse grid). The tet solver ([`crate::xpbd::Solver`]) drives them when
//! `solver.scheme` is `Newton`.

mod block_lanes;
mod block_matrix;
mod coarse_assembly;
mod coarse_grid;
mod coarse_level;
mod coarse_pieces;
mod coarse_rebuild;
mod coarse_system;
mod eval_lanes;
mod hessian;
mod newton_report;
mod params;
mod pcg;
mod product_lanes;
mod product_parts;
mod rest_tet;
mod tet_evals;
mod tet_tangent;
mod two_level;
mod workspace;

pub use coarse_grid::CoarseGrid;
pub use coarse_level::CoarseLevel;
pub use coarse_system::{CoarseError, CoarseSystem};
pub use newton_report::{FrameCost, NewtonReport};
pub use params::{CoarseRefresh, NewtonParams, Scheme, Smoother};
pub use pcg::{CgReport, dot, pcg};
pub use rest_tet::RestTet;
pub use tet_tangent::TetTangent;
pub(crate) use workspace::FirstTrial;
pub use workspace::NewtonWorkspace;
