//! What the renderer is told of the scalpel: the tool's own closed mesh as a plain
//! [`ToolMesh`], and where the solver's tool and its contact spheres are this frame as a
//! [`ToolState`] (incise-xr knows nothing of incise-scalpel).

use glam::Mat4;
use incise_scalpel::Tool;
use incise_sim::Solver;
use incise_sim::contact::{PlacedTool, ToolPose};
use incise_xr::ToolMesh;
use incise_xr::frame::ToolState;

/// The render mesh of `tool` (tool frame, m), flat-shaded.
pub fn tool_mesh(tool: &Tool) -> ToolMesh {
    let (positions, triangles) = tool.render_mesh();
    ToolMesh::from_triangles(&positions, &triangles)
}

/// The rigid placement of the tool frame at `pose`.
pub fn pose_matrix(pose: &ToolPose) -> Mat4 {
    Mat4::from_rotation_translation(pose.rotation, pose.position)
}

/// The solver's tool where it ended the last frame (mesh placement and contact spheres);
/// nothing drawn when no tool is attached.
pub fn tool_state(solver: &Solver) -> ToolState {
    let Some(m) = solver.tool() else {
        return ToolState::default();
    };
    let placed = PlacedTool::new(&m.tool, &m.to);
    ToolState {
        transform: Some(pose_matrix(&m.to)),
        spheres: placed
            .spheres
            .iter()
            .map(|s| (s.centre, s.radius))
            .collect(),
    }
}
