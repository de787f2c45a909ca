//! The chest experiment of Nakao et al. 2003 (PHYSICS.md §2.6, Figs. 14–17): an incision
//! along the sternum of a torso-like wall under 4 % tension, the mechanics localised
//! around the blade at a fixed level (4 or 6) or by the refresh-rate manager, each loop's
//! free nodes, level and time split recorded.

use glam::DVec3;
use serde::Serialize;

use super::measure::{MeshCounts, counts};
use super::{BladePose, CutParams, Cutter};
use crate::generate::{
    CHEST_HEART_NODES, CHEST_LENGTH, CHEST_WALL_AXES, CHEST_WALL_NODES, CHEST_WALL_THICKNESS, chest,
};
use crate::mass_spring::{
    AxisMask, Clock, LocalLoop, LocalLoopParams, MassSpringError, MassSpringModel,
    MassSpringParams, Tension,
};
use crate::mesh::TetMesh;

/// The paper's tension coefficient for the chest: 4 %.
pub const CHEST_TENSION: f64 = 0.04;

/// The chest model: the wall under 4 % tension, held along its two lateral edges and its
/// two ends; the heart held whole (it is not cut; it is there for the counts).
pub fn chest_model() -> Result<MassSpringModel, MassSpringError> {
    let (mesh, _) = TetMesh::from_raw(chest()).map_err(|e| MassSpringError::BadParameter {
        field: "mesh",
        msg: e.to_string(),
    })?;
    let params = MassSpringParams {
        tension: Tension::Uniform(CHEST_TENSION),
        ..MassSpringParams::default()
    };
    let mut m = MassSpringModel::new(&mesh, params)?;
    let [na, nl, nt] = CHEST_WALL_NODES;
    let wall = na * nl * nt;
    let held: Vec<u32> = (0..wall)
        .filter(|&v| {
            let (i, j) = (v % na, (v / na) % nl);
            i == 0 || i == na - 1 || j == 0 || j == nl - 1
        })
        .chain(wall..wall + CHEST_HEART_NODES.pow(3))
        .map(|v| v as u32)
        .collect();
    m.fix(&held, AxisMask::ALL)?;
    Ok(m)
}

/// The vertical blade through the wall at the sternum, at `y` along the body, m.
pub fn sternum_blade(y: f64) -> BladePose {
    // The inner surface at the sternum (θ = π/2) is at z = b.
    let top = CHEST_WALL_AXES[1] as f64;
    // Slightly off the node column (x = 0.0013), as a hand would be.
    let x = 0.0013;
    BladePose {
        heel: DVec3::new(x, y, top - 0.005),
        tip: DVec3::new(x, y, top + CHEST_WALL_THICKNESS as f64 + 0.005),
    }
}

/// One loop (a 10 ms visual frame) of the chest experiment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChestLoop {
    /// Level the localisation reached.
    pub level: u32,
    /// Nodes integrated.
    pub free_nodes: usize,
    /// Nearest node, hierarchy, stopping nodes, ms.
    pub localise_ms: f64,
    /// Forces over the loop's steps, ms.
    pub force_ms: f64,
    /// Integration over the loop's steps, ms.
    pub integrate_ms: f64,
    /// The blade advance, ms.
    pub cut_ms: f64,
}

impl ChestLoop {
    /// The loop's four parts added up, ms.
    pub fn total_ms(&self) -> f64 {
        self.localise_ms + self.force_ms + self.integrate_ms + self.cut_ms
    }
}

/// What one run of the chest incision measured.
#[derive(Debug, Clone, Serialize)]
pub struct ChestRun {
    /// Counts before the incision.
    pub before: MeshCounts,
    /// Counts after it.
    pub after: MeshCounts,
    /// Every loop, in order.
    pub loops: Vec<ChestLoop>,
}

/// Settle the chest for `settle` s (whole mesh), then cut along the sternum from
/// y = −6 cm at 5 cm/s for `loops` loops of 10 ms, localised by `local`, the tool at the
/// middle of the blade's edge.
pub fn run_chest_cut<C: Clock>(
    mut model: MassSpringModel,
    local: LocalLoopParams,
    clock: C,
    loops: usize,
    settle: f64,
) -> ChestRun {
    model.advance(settle);
    let before = counts(&model);
    let mut cutter = Cutter::new(CutParams::default());
    let mut local = LocalLoop::new(local, clock);
    let y0 = -0.06_f64.max(-0.5 * CHEST_LENGTH as f64);
    cutter.begin(&model, sternum_blade(y0));
    let frame = 0.01;
    let mut out = Vec::with_capacity(loops);
    for k in 1..=loops {
        let pose = sternum_blade(y0 + 0.05 * frame * k as f64);
        let cut_ms = cutter.advance(&mut model, pose).ms;
        let steps = (frame / model.stable_dt()).ceil().max(1.0) as u32;
        let s = local.frame(
            &mut model,
            (pose.heel + pose.tip) * 0.5,
            frame / steps as f64,
            steps,
        );
        out.push(ChestLoop {
            level: s.level(),
            free_nodes: s.free_nodes,
            localise_ms: s.localise_ms,
            force_ms: s.force_ms,
            integrate_ms: s.integrate_ms,
            cut_ms,
        });
    }
    cutter.end();
    ChestRun {
        before,
        after: counts(&model),
        loops: out,
    }
}
