//! XPBD small-steps solver for Neo-Hookean tets (PHYSICS.md §1.2), CPU reference.

mod coloring;
mod flop_count;
mod frame;
mod implicit_step;
mod lane;
#[cfg(target_arch = "x86_64")]
pub(crate) mod lane_avx;
// The AVX-512 intrinsics are stable since Rust 1.89 (build.rs); before it the AVX lanes
// serve alone.
#[cfg(all(target_arch = "x86_64", incise_avx512))]
#[allow(clippy::incompatible_msrv)]
mod lane_avx512;
pub(crate) mod lane_nodes;
#[cfg(all(target_arch = "x86_64", incise_avx512))]
#[allow(clippy::incompatible_msrv)]
mod lane_pair_nodes;
mod lane_pass;
mod lane_slots;
pub(crate) mod lanes;
mod locality;
mod neo_hookean;
mod node_records;
mod params;
mod release_schedule;
mod rest_free;
pub(crate) mod rest_free_lanes;
mod retune;
mod run_projector;
mod shared_nodes;
mod solver;
mod stability;
mod strain;
mod sweep_plan;
mod tet_constraint;
mod tet_slot;

pub use coloring::greedy_tet_colors;
pub use flop_count::{LN_FLOPS, NODE_FLOPS_PER_SUBSTEP, projection_flops};
pub use frame::FrameStats;
pub use implicit_step::MAX_SPLITS;
pub use locality::TetOrder;
pub use neo_hookean::{
    ConstraintPair, TetProjection, TetTerms, deformation_gradient, det_gradient,
};
pub use params::{CpuKernel, CpuSweep, DEFAULT_RELEASE_INTERVAL, SolverError, SolverParams};
pub use release_schedule::release_checks;
pub use rest_free::{J_MIN, log_volume, shape_constraint, shape_energy, volume_constraint};
pub use solver::{NodeKind, Solver};
pub use stability::{MAX_STIFFNESS_NUMBER, stiffness_number, substeps_needed};
pub use strain::{Strain, cofactor, displacement_gradient, log1p_excess};
pub use sweep_plan::SWEEP_BLOCKS;
pub use tet_constraint::project_tet;
