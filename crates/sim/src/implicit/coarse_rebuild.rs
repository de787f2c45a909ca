//! The coarse level rebuilt on the pieces a cut leaves (docs/physics-notes.md, "The coarse
//! level after a cut"): the grid split per piece ([`CoarseGrid::new`]), the pattern of its
//! matrix and its assembly, computed on a thread of its own while the solver steps on, and
//! taken at the next refresh, so a tear costs no frame the rebuild's time. The rebuild
//! starts at one refresh and is always taken at the next (waiting for it if needed), so
//! the result does not depend on how fast the machine is.

use std::sync::Arc;
use std::thread::JoinHandle;

use glam::Vec3;

use super::coarse_assembly::CoarseAssembly;
use super::coarse_grid::{CoarseGrid, NodeWeights};
use super::coarse_system::{CoarseError, CoarseSystem};
use super::rest_tet::RestTet;

/// What every rebuild reads: the body at rest.
pub struct RebuildInputs {
    /// Rest positions.
    pub points: Vec<Vec3>,
    /// The nodes solved for.
    pub free: Vec<bool>,
    /// Lumped masses.
    pub mass: Vec<f32>,
    /// `1/h²`.
    pub inv_h2: f32,
    /// Edge of the coarse cubes, m.
    pub cell: f32,
    /// Every tet.
    pub tets: Vec<RestTet>,
    /// Their shape gradients.
    pub b: Vec<[Vec3; 4]>,
}

/// A rebuilt coarse level, its matrix holding only the mass until a refresh fills it.
pub struct Rebuilt {
    /// The grid on the pieces.
    pub grid: CoarseGrid,
    /// Its matrix's pattern, factorised on the mass alone.
    pub system: CoarseSystem,
    /// The tets' corner pairs on it.
    pub assembly: CoarseAssembly,
}

/// A rebuild under way: `None` when the pieces are the grid's or need more than the
/// most coarse nodes allowed.
pub struct PendingRebuild(JoinHandle<Result<Option<Rebuilt>, CoarseError>>);

impl PendingRebuild {
    /// Start rebuilding on the pieces the tets marked `live` leave; `current`: the grid's
    /// weights now (an unchanged grid is not rebuilt), `max_nodes`: the most it may have.
    pub fn start(
        inputs: Arc<RebuildInputs>,
        live: Vec<bool>,
        current: Vec<NodeWeights>,
        max_nodes: usize,
    ) -> Self {
        PendingRebuild(std::thread::spawn(move || {
            rebuild(&inputs, &live, &current, max_nodes)
        }))
    }

    /// Wait for the rebuild and take it.
    pub fn take(self) -> Result<Option<Rebuilt>, CoarseError> {
        self.0
            .join()
            .unwrap_or_else(|_| Err(CoarseError::new("the coarse rebuild thread failed")))
    }
}

/// The grid on the pieces `live` leaves, with its pattern and assembly, unless it is
/// `current` or larger than `max_nodes`.
fn rebuild(
    inputs: &RebuildInputs,
    live: &[bool],
    current: &[NodeWeights],
    max_nodes: usize,
) -> Result<Option<Rebuilt>, CoarseError> {
    let RebuildInputs { points, free, .. } = inputs;
    let grid = CoarseGrid::new(points, free, inputs.cell, (&inputs.tets, live));
    if grid.count > max_nodes || grid.weights == current {
        return Ok(None);
    }
    let (system, assembly) = CoarseSystem::with_assembly(
        &grid,
        (&inputs.tets, &inputs.b),
        (&inputs.mass, inputs.inv_h2),
    )?;
    Ok(Some(Rebuilt {
        grid,
        system,
        assembly,
    }))
}
