//! An exercise's tolerance band (lateral, depth) and the resolution lengths its metrics
//! are read at (docs/scoring.md).

use incise_sim::TetMesh;

use super::model::Exercise;

/// The tolerance band and the resolution lengths of the metrics.
pub(super) struct Band {
    /// Lateral tolerance `w`, m.
    pub lateral: f64,
    /// Target depth `d*`, m.
    pub target: f64,
    /// Deepest allowed cut `d* + δ`, m.
    pub max_depth: f64,
    /// Mean tet edge `h`, m.
    pub tet_edge: f64,
    /// Samples within this arc length of a cut count as cut (a tet spans about one
    /// edge): `h/2`, m.
    pub window: f64,
}

impl Band {
    /// The band of `exercise` on `mesh`.
    pub(super) fn of(exercise: &Exercise, mesh: &TetMesh) -> Band {
        let tet_edge = mesh.mean_edge_length() as f64;
        Band {
            lateral: exercise.tolerance.lateral as f64,
            target: exercise.depth as f64,
            max_depth: (exercise.depth + exercise.tolerance.depth) as f64,
            tet_edge,
            window: 0.5 * tet_edge,
        }
    }
}
