//! Procedural meshes: structured hex grids split into tets, boxes and beams, the Nakao
//! plate and the intestine segment with its skin.

mod block;
mod hex_grid;
mod intestine;
mod plate;

pub use block::{beam, block};
pub use hex_grid::hex_grid_tets;
pub use intestine::{Centreline, IntestineParams, PAPER_TETS, intestine};
pub use plate::plate;
