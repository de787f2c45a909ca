//! Vertex Block Descent (Chen, Liu, Yang & Yuksel, "Vertex Block Descent", SIGGRAPH
//! 2024, arXiv:2403.06321) on the CPU for the rest-free Neo-Hookean energy of
//! [`crate::xpbd`]: implicit Euler by per-vertex Newton steps in coloured Gauss–Seidel.

mod chebyshev;
mod coloring;
mod energy;
mod params;
mod solver;

pub use chebyshev::chebyshev_omega;
pub use coloring::greedy_vertex_colors;
pub use energy::{energy_density, piola, shape_gradients, vertex_gradient_hessian};
pub use params::{InitialGuess, VbdError, VbdParams};
pub use solver::{VbdFrameStats, VbdSolver};
