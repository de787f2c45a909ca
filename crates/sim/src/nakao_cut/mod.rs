//! Cutting the mass-spring model with a blade (Nakao et al. 2003, PHYSICS.md §2.3–2.4):
//! the partial plane the blade sweeps between two poses, the edges it crosses, node
//! displacement onto its boundary, minimal subdivision (4 or 6 tets per crossed tet, the
//! split chosen by dihedral angles), remodelling by node duplication, and smoothing; plus
//! the non-adaptive baselines for comparison (fixed-order minimal, and after Bielser &
//! Gross 2000 with quadrilateral centres).

mod bisect;
mod blade;
mod chest_experiment;
mod chest_slab;
mod crossing;
mod cutter;
pub mod invariants;
pub mod measure;
mod node_move;
mod plate_experiment;
mod quad_centre;
mod separate;
mod smooth;
mod snap;
mod split_order;

pub use blade::{BladePose, SweptRegion};
pub use chest_experiment::{
    CHEST_TENSION, ChestLoop, ChestRun, chest_model, run_chest_cut, sternum_blade,
};
pub use chest_slab::{CHEST_SLAB_SIZE, chest_slab_model, slab_blade};
pub use cutter::{CutParams, CutReport, Cutter, Subdivision};
pub use plate_experiment::{PlateCutResult, PlateCutSetup, plate_model, run_plate_cut};
pub use split_order::SplitQuality;
