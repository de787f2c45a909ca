//! Procedural meshes: structured hex grids split into tets, boxes and beams, the Nakao
//! plate, the torso-like chest of the Nakao experiment and the intestine segment with
//! its skin.

mod block;
mod chest;
mod hex_grid;
mod intestine;
mod plate;

pub use block::{beam, block};
pub use chest::{
    CHEST_ARC, CHEST_HEART, CHEST_HEART_NODES, CHEST_LENGTH, CHEST_WALL_AXES, CHEST_WALL_NODES,
    CHEST_WALL_THICKNESS, chest,
};
pub use hex_grid::hex_grid_tets;
pub use intestine::{Centreline, IntestineParams, PAPER_TETS, intestine};
pub use plate::plate;
