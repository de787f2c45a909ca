//! Errors of the rheological body model.

use crate::error::MeshError;
use crate::selection::SelectionError;

/// Why a rheological body or run could not be set up or went wrong.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RheologyError {
    /// A material parameter is out of range.
    #[error("rheology material `{material}`: {field} {message}")]
    BadMaterial {
        /// Material name.
        material: String,
        /// Offending field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A fixed step is above the explicit RK4 stability limit.
    #[error(
        "RK4 step {step:e} s exceeds the explicit stability limit {limit:e} s; use a step \
         below the limit or let the body choose its substeps"
    )]
    StepTooLarge {
        /// The step asked for, s.
        step: f64,
        /// The stability limit, s.
        limit: f64,
    },
    /// A saved state does not fit the body (saved from another body).
    #[error("the saved state has {saved} values but the body has {values}")]
    StateMismatch {
        /// Values of the saved state.
        saved: usize,
        /// Values of the body's state.
        values: usize,
    },
    /// The state became NaN or infinite.
    #[error("the simulation diverged (non-finite state) at t = {time} s")]
    Diverged {
        /// Time of the failing step, s.
        time: f64,
    },
    /// A material index does not name a material of the body.
    #[error("material index {index} is out of range: the body has {count} materials")]
    MaterialIndex {
        /// The index.
        index: usize,
        /// Number of materials.
        count: usize,
    },
    /// A region's or pin's node selection is unusable.
    #[error("{what}: {source}")]
    Selection {
        /// Which selection (e.g. "region 2").
        what: String,
        /// The selection error.
        source: SelectionError,
    },
    /// A material region covers no tet.
    #[error("material region {region} covers no tet: {why}")]
    EmptyRegion {
        /// Index of the region.
        region: usize,
        /// Why (what it selected).
        why: String,
    },
    /// The generated specimen mesh is invalid.
    #[error("specimen mesh: {0}")]
    Mesh(#[from] MeshError),
}
