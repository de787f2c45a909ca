//! report.json: what a run did, frame by frame, in a form scripts can compare.

use std::path::Path;

use anyhow::{Context, Result};
use incise_sim::xpbd::FrameStats;
use serde::Serialize;

/// One frame's line in the report.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRecord {
    /// Solver statistics.
    #[serde(flatten)]
    pub stats: FrameStats,
    /// Wall time of the frame (substeps + stress + release), ms.
    pub wall_ms: f64,
    /// GPU kernel time of the frame (timestamps), ms; absent on the CPU or without them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu_ms: Option<f64>,
}

/// The whole run report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Scene name.
    pub scene: String,
    /// Scene file.
    pub scene_file: String,
    /// "completed" or "failed".
    pub status: String,
    /// The error that stopped the run, if any.
    pub error: Option<String>,
    /// Mesh figures.
    pub mesh: MeshInfo,
    /// Material name and values.
    pub material: MaterialInfo,
    /// Solver settings in use.
    pub solver: incise_sim::SolverParams,
    /// Worker threads used.
    pub threads: usize,
    /// Device the solver ran on: "cpu" or the GPU adapter's name, backend and type.
    pub device: String,
    /// Per-frame records.
    pub frames: Vec<FrameRecord>,
    /// Snapshot files written (relative to the report).
    pub snapshots: Vec<String>,
}

/// Mesh figures for the report.
#[derive(Debug, Clone, Serialize)]
pub struct MeshInfo {
    /// Nodes.
    pub nodes: usize,
    /// Tets.
    pub tets: usize,
    /// Tets re-oriented on load.
    pub reoriented_tets: usize,
    /// Colours of the parallel projection.
    pub colors: usize,
    /// Skin vertices.
    pub skin_vertices: usize,
    /// Skin triangles.
    pub skin_triangles: usize,
    /// Pinned nodes.
    pub pinned_nodes: usize,
    /// Grabbed nodes.
    pub grabbed_nodes: usize,
    /// Reader warnings.
    pub warnings: Vec<String>,
}

/// Material for the report.
#[derive(Debug, Clone, Serialize)]
pub struct MaterialInfo {
    /// Preset name or "custom".
    pub name: String,
    /// E, ν, ρ.
    #[serde(flatten)]
    pub values: incise_sim::Material,
    /// Shear modulus μ, Pa.
    pub mu: f32,
    /// Lamé λ, Pa.
    pub lambda: f32,
}

impl Report {
    /// Write as pretty JSON, atomically (temp file + rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        let json = serde_json::to_vec_pretty(self)?;
        incise_sim::io::write_atomic(path, &json)
            .with_context(|| format!("writing {}", path.display()))
    }
}
