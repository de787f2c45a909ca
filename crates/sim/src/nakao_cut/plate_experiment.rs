//! The plate experiment of Nakao et al. 2003 (PHYSICS.md §2.6): a 16 × 16 × 0.4 cm plate
//! under tension, its rim held and its surface nodes held in depth, cut along one straight
//! line; the wound opens to a new equilibrium.

use std::time::Instant;

use glam::DVec3;
use serde::Serialize;

use super::measure::{MeshCounts, counts, cut_surface_area, opening_width, worst_new_tet_quality};
use super::{BladePose, CutParams, Cutter, Subdivision};
use crate::generate::plate;
use crate::mass_spring::{AxisMask, MassSpringError, MassSpringModel, MassSpringParams, Tension};
use crate::mesh::TetMesh;

/// Half the plate's side, m.
const HALF: f64 = 0.08;
/// Plate thickness, m.
const THICKNESS: f64 = 0.004;

/// One run of the plate experiment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlateCutSetup {
    /// Tension coefficient s of every edge (eq. 3).
    pub tension: f64,
    /// Cutter settings (adaptive or non-adaptive subdivision and its knobs).
    pub cut: CutParams,
    /// Start of the cut line on the plate (x, y), m.
    pub start: [f64; 2],
    /// End of the cut line (x, y), m.
    pub end: [f64; 2],
    /// Blade advance per 10 ms visual loop, m.
    pub advance: f64,
    /// Simulated time before the cut (the tensioned plate settles), s.
    pub settle_before: f64,
    /// Simulated time after the cut (the wound opens), s.
    pub settle_after: f64,
}

impl PlateCutSetup {
    /// The reference cut: a 14 cm line through the middle, slightly oblique so that it
    /// meets edges at every crossing parameter, 2 mm per 10 ms loop (0.2 m/s), 0.2 s
    /// settling before and 0.8 s after (the wound's kinetic energy is then below 1e-15 J).
    pub fn reference(tension: f64, subdivision: Subdivision) -> Self {
        PlateCutSetup {
            tension,
            cut: CutParams {
                subdivision,
                ..CutParams::default()
            },
            start: [-0.07, -0.0048],
            end: [0.07, 0.0055],
            advance: 0.002,
            settle_before: 0.2,
            settle_after: 0.8,
        }
    }

    /// Middle of the cut at mid-depth, m.
    pub fn centre(&self) -> DVec3 {
        DVec3::new(
            0.5 * (self.start[0] + self.end[0]),
            0.5 * (self.start[1] + self.end[1]),
            0.5 * THICKNESS,
        )
    }
}

/// What one run measured.
#[derive(Debug, Clone, Serialize)]
pub struct PlateCutResult {
    /// The setup.
    pub setup: PlateCutSetup,
    /// Counts before the cut.
    pub before: MeshCounts,
    /// Counts after the cut.
    pub after: MeshCounts,
    /// Total cut-surface area after the wound opened, m².
    pub cut_area: f64,
    /// Wound opening at the middle of the cut, m.
    pub opening_width: f64,
    /// Slowest 10 ms loop while cutting (blade advance + 10 ms of simulation), ms.
    pub max_loop_ms: f64,
    /// Slowest blade advance (subdivision and remodelling), ms.
    pub max_cut_ms: f64,
    /// Smallest dihedral angle of the tets the cut created, degrees.
    pub worst_dihedral_deg: f64,
    /// Smallest aspect-ratio quality (radius ratio `3 r_in / R_circ`, 1 = regular) of the
    /// tets holding a node the cut created.
    pub worst_new_radius_ratio: f64,
    /// Kinetic energy at the end, J (how settled the wound is).
    pub final_kinetic_energy: f64,
    /// Edges split at a crossing, over the whole cut.
    pub split_edges: usize,
    /// Nodes duplicated to open the cut (split points and original nodes on the cut).
    pub duplicated_nodes: usize,
    /// Nodes moved onto the cut boundary or plane (adaptive).
    pub moved_nodes: usize,
}

/// The tensioned plate model: rim nodes held, every node held in depth (all nodes of the
/// two-layer plate lie on its surfaces).
pub fn plate_model(tension: f64) -> Result<MassSpringModel, MassSpringError> {
    let (mesh, _) = TetMesh::from_raw(plate()).map_err(|e| MassSpringError::BadParameter {
        field: "mesh",
        msg: e.to_string(),
    })?;
    let params = MassSpringParams {
        tension: Tension::Uniform(tension),
        ..MassSpringParams::default()
    };
    let mut model = MassSpringModel::new(&mesh, params)?;
    let all: Vec<u32> = (0..model.node_count() as u32).collect();
    model.fix(&all, AxisMask::Z)?;
    let rim: Vec<u32> = all
        .iter()
        .copied()
        .filter(|&i| {
            let p = model.positions()[i as usize];
            p.x.abs().max(p.y.abs()) > HALF - 1e-6
        })
        .collect();
    model.fix(&rim, AxisMask::ALL)?;
    Ok(model)
}

/// Run the experiment: settle, cut along the line loop by loop, let the wound open.
pub fn run_plate_cut(
    setup: &PlateCutSetup,
) -> Result<(PlateCutResult, MassSpringModel), MassSpringError> {
    let mut model = plate_model(setup.tension)?;
    model.advance(setup.settle_before);
    let before = counts(&model);
    let mut cutter = Cutter::new(setup.cut.clone());
    let a = DVec3::new(setup.start[0], setup.start[1], 0.0);
    let b = DVec3::new(setup.end[0], setup.end[1], 0.0);
    let length = (b - a).length();
    let dir = (b - a) / length;
    // A vertical blade reaching through the whole thickness.
    let blade = |p: DVec3| BladePose {
        heel: p - DVec3::Z * 0.002,
        tip: p + DVec3::Z * (THICKNESS + 0.002),
    };
    cutter.begin(&model, blade(a));
    let loops = (length / setup.advance).ceil().max(1.0) as usize;
    let (mut max_loop_ms, mut max_cut_ms) = (0.0f64, 0.0f64);
    let mut worst = f64::INFINITY;
    let (mut split_edges, mut duplicated_nodes, mut moved_nodes) = (0, 0, 0);
    for k in 1..=loops {
        let s = (k as f64 * setup.advance).min(length);
        let t0 = Instant::now();
        let r = cutter.advance(&mut model, blade(a + dir * s));
        model.advance(0.01);
        max_loop_ms = max_loop_ms.max(t0.elapsed().as_secs_f64() * 1e3);
        max_cut_ms = max_cut_ms.max(r.ms);
        worst = worst.min(r.worst_dihedral_deg);
        split_edges += r.split_edges;
        duplicated_nodes += r.duplicated_nodes;
        moved_nodes += r.moved_nodes;
    }
    cutter.end();
    model.advance(setup.settle_after);
    let after = counts(&model);
    let opening = opening_width(&model, setup.centre(), 0.6 * 0.16 / 24.0).unwrap_or(0.0);
    let result = PlateCutResult {
        setup: setup.clone(),
        before,
        after,
        cut_area: cut_surface_area(&model),
        opening_width: opening,
        max_loop_ms,
        max_cut_ms,
        worst_dihedral_deg: worst,
        worst_new_radius_ratio: worst_new_tet_quality(&model, before.nodes).unwrap_or(1.0),
        final_kinetic_energy: model.kinetic_energy(),
        split_edges,
        duplicated_nodes,
        moved_nodes,
    };
    Ok((result, model))
}
