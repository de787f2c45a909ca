//! The report head of the CPU edge methods (Nakao, rheology): the mesh figures from the
//! body's counts, no colours or grabs, the scene's solver settings and the method's own
//! device line.

use std::path::Path;

use incise_sim::MeshBuildReport;

use crate::report::{MeshInfo, Report};
use crate::scene::Method;
use crate::scene::Scene;

/// The counts an edge method's report head gives.
#[derive(Debug, Clone, Copy)]
pub struct HeadCounts {
    /// Nodes of the body.
    pub nodes: usize,
    /// Tets of the body.
    pub tets: usize,
    /// Vertices of the drawn skin (0: the method draws none).
    pub skin_vertices: usize,
    /// Triangles of the drawn skin.
    pub skin_triangles: usize,
    /// Nodes the scene's pins fix.
    pub pinned: usize,
}

/// The report head of `scene` (file `path`) for model name and method `model`, with the
/// body's `counts`, the mesh build's re-orientations and warnings, and the method's
/// device, e.g. "cpu (mass-spring)" (`model.0` in parentheses).
pub fn edge_method_head(
    scene: &Scene,
    path: &Path,
    model: (&str, Method),
    mesh_report: &MeshBuildReport,
    counts: HeadCounts,
) -> Report {
    let mut report = Report::begin(
        scene,
        path,
        model,
        MeshInfo {
            nodes: counts.nodes,
            tets: counts.tets,
            reoriented_tets: mesh_report.reoriented_tets,
            colors: 0,
            skin_vertices: counts.skin_vertices,
            skin_triangles: counts.skin_triangles,
            pinned_nodes: counts.pinned,
            grabbed_nodes: 0,
            warnings: mesh_report.warnings.clone(),
        },
        scene.solver.clone(),
    );
    report.device = format!("cpu ({})", model.0);
    report
}
