//! Per-tet stress: polar decomposition, Cauchy stress σ_T and von Mises (PHYSICS.md §1.3).

mod polar;
mod von_mises;

pub use polar::extract_rotation;
pub use von_mises::{TetStress, tet_stress};
