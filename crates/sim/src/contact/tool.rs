//! The tool as the solver sees it (PHYSICS.md §1.5): plain primitives in the tool's own
//! frame — spheres along the cutting edge, boxes for the non-cutting body — and the
//! tool's pose, interpolated per substep.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

use super::ContactError;

/// Rigid placement of the tool: tool-frame point `p` sits at `position + rotation · p`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToolPose {
    /// Origin of the tool frame in world coordinates, m.
    pub position: Vec3,
    /// Orientation of the tool frame (unit quaternion).
    pub rotation: Quat,
}

impl Default for ToolPose {
    fn default() -> Self {
        ToolPose {
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        }
    }
}

impl ToolPose {
    /// A pose from a position and a rotation.
    pub fn new(position: Vec3, rotation: Quat) -> Self {
        ToolPose { position, rotation }
    }

    /// World coordinates of tool-frame point `p`.
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.position + self.rotation * p
    }

    /// Tool-frame coordinates of world point `x`.
    pub fn inverse_transform_point(&self, x: Vec3) -> Vec3 {
        self.rotation.inverse() * (x - self.position)
    }

    /// The pose a fraction `s` of the way to `to`: translation lerp, rotation slerp
    /// (continuous contact: the tool moves within a frame, not only between frames).
    pub fn interpolate(&self, to: &ToolPose, s: f32) -> ToolPose {
        ToolPose {
            position: self.position.lerp(to.position, s),
            rotation: self.rotation.slerp(to.rotation, s).normalize(),
        }
    }
}

/// A contact sphere in the tool frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToolSphere {
    /// Centre in the tool frame, m.
    pub centre: Vec3,
    /// Radius, m.
    pub radius: f32,
    /// Part of the cutting edge: tets it presses may be released by the stress
    /// criterion (see `CutZone`); a non-cutting sphere only pushes.
    pub cutting: bool,
}

/// An oriented box of the tool's non-cutting body in the tool frame (pushes, never cuts).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToolBox {
    /// Centre in the tool frame, m.
    pub centre: Vec3,
    /// Orientation of the box axes in the tool frame.
    pub rotation: Quat,
    /// Half side lengths along the box axes, m.
    pub half_extents: Vec3,
}

/// Everything the solver needs of a tool: its primitives and its friction.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ContactTool {
    /// Spheres (cutting edge and any non-cutting spheres).
    pub spheres: Vec<ToolSphere>,
    /// Boxes of the non-cutting body.
    pub boxes: Vec<ToolBox>,
    /// Coulomb-like positional friction coefficient (tangential correction up to
    /// `friction ×` the normal correction), dimensionless.
    pub friction: f32,
}

impl ContactTool {
    /// Ok, or the first bad primitive and why.
    pub fn validate(&self) -> Result<(), ContactError> {
        if self.spheres.is_empty() && self.boxes.is_empty() {
            return Err(ContactError::Empty);
        }
        for (i, s) in self.spheres.iter().enumerate() {
            if !s.centre.is_finite() {
                return Err(ContactError::bad(
                    format!("spheres[{i}].centre"),
                    "must be finite",
                ));
            }
            if !(s.radius.is_finite() && s.radius > 0.0) {
                return Err(ContactError::bad(
                    format!("spheres[{i}].radius"),
                    format!("must be a positive length in m, got {}", s.radius),
                ));
            }
        }
        for (i, b) in self.boxes.iter().enumerate() {
            if !b.centre.is_finite() {
                return Err(ContactError::bad(
                    format!("boxes[{i}].centre"),
                    "must be finite",
                ));
            }
            if !(b.rotation.is_finite() && (b.rotation.length() - 1.0).abs() < 1e-3) {
                return Err(ContactError::bad(
                    format!("boxes[{i}].rotation"),
                    "must be a unit quaternion",
                ));
            }
            let h = b.half_extents;
            if !(h.is_finite() && h.min_element() > 0.0) {
                return Err(ContactError::bad(
                    format!("boxes[{i}].half_extents"),
                    format!("must be positive lengths in m, got {h}"),
                ));
            }
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(ContactError::bad(
                "friction",
                format!("must be >= 0, got {}", self.friction),
            ));
        }
        Ok(())
    }

    /// Whether any sphere is part of the cutting edge.
    pub fn has_cutting_edge(&self) -> bool {
        self.spheres.iter().any(|s| s.cutting)
    }

    /// The same tool with a dull edge: the edge spheres still push, but none cuts.
    pub fn dulled(&self) -> ContactTool {
        ContactTool {
            spheres: self
                .spheres
                .iter()
                .map(|s| ToolSphere {
                    cutting: false,
                    ..*s
                })
                .collect(),
            ..self.clone()
        }
    }
}

/// Where the stress criterion may release tets.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum CutZone {
    /// Any live tet over the threshold (tearing; PHYSICS.md §1.4 as written).
    #[default]
    Anywhere,
    /// Only tets with a node that came within `reach` (m) of a cutting sphere's surface
    /// during the frame: the blade's edge concentrates stress beyond what the mesh
    /// resolves, the handle and blade flat push without cutting.
    NearEdge {
        /// Distance from a cutting sphere's surface, m.
        reach: f32,
    },
}
