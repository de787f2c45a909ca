//! Tool–tissue contact (PHYSICS.md §1.5). The scalpel enters the solver as plain data: a
//! [`ContactTool`] (spheres along the cutting edge, boxes for the body, in the tool's
//! frame) and its pose at the start and end of each frame; the solver interpolates the
//! pose per substep and projects nodes out of the tool.

mod projection;
mod sdf;
mod tool;

pub use projection::{NodeContact, ON_SURFACE, project_node};
pub use sdf::{PlacedTool, WorldBox, WorldSphere, box_distance, sphere_distance};
pub use tool::{ContactTool, CutZone, ToolBox, ToolPose, ToolSphere};

/// A tool the solver cannot use.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContactError {
    /// No spheres and no boxes.
    #[error("the tool has no contact primitives (no spheres, no boxes)")]
    Empty,
    /// A field out of range.
    #[error("tool {field}: {msg}")]
    BadField {
        /// Which field (e.g. `spheres[3].radius`).
        field: String,
        /// Why.
        msg: String,
    },
}

impl ContactError {
    pub(crate) fn bad(field: impl Into<String>, msg: impl Into<String>) -> Self {
        ContactError::BadField {
            field: field.into(),
            msg: msg.into(),
        }
    }
}

/// The tool attached to a solver and where it goes this frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolMotion {
    /// The tool.
    pub tool: ContactTool,
    /// Pose at the start of the frame.
    pub from: ToolPose,
    /// Pose at the end of the frame.
    pub to: ToolPose,
}

impl ToolMotion {
    /// The tool placed at the end of substep `s` of `n` (`s = 0`: the frame's start).
    pub fn placed_at(&self, s: u32, n: u32) -> PlacedTool {
        let pose = self.from.interpolate(&self.to, s as f32 / n as f32);
        PlacedTool::new(&self.tool, &pose)
    }
}
