//! Per-tet stress: the Cauchy stress of the model (default) or the seed's eq. 3 with its
//! polar decomposition; von Mises (PHYSICS.md §1.3).

mod cauchy;
pub mod closed_form;
mod polar;
mod von_mises;

pub use cauchy::{StressMeasure, cauchy_stress, mean_stress, von_mises};
pub use polar::extract_rotation;
pub use von_mises::{TetStress, tet_stress};
