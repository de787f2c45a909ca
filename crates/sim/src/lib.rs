//! incise-sim: the simulation core of incise.
//!
//! Tet meshes and their file formats, materials, the XPBD Neo-Hookean solver (CPU
//! reference), Cauchy/von Mises stress and stress-based cutting. No windowing, no XR:
//! the scalpel enters the solver as plain sphere data. Equations are cited from
//! `PHYSICS.md` (the project's restatement of the three source papers).

pub mod contact;
pub mod cutting;
pub mod error;
pub mod generate;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod grab;
pub mod implicit;
pub mod io;
pub mod mass_spring;
pub mod material;
pub mod mesh;
pub mod nakao_cut;
pub mod rheology;
pub mod ron_file;
pub mod selection;
pub mod skin;
pub mod stress;
pub mod thread_team;
pub mod vbd;
pub mod xpbd;

pub use error::MeshError;
pub use material::Material;
pub use mesh::{MeshBuildReport, RawMesh, TetMesh, TriSurface};
pub use xpbd::{Solver, SolverParams};
