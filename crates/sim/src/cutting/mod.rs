//! Cutting by constraint release (PHYSICS.md §1.4).

mod cut_state;

pub use cut_state::{CutState, ReleaseEvent};
