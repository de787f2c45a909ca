//! Signed distances of the tool's primitives (PHYSICS.md §1.5): `d(x) = ‖x − c‖ − r` for
//! a sphere, the exact box distance for the body; negative inside. The WGSL twin is in
//! `gpu/shaders/contact.wgsl`.

use glam::{Mat3, Vec3};

use super::tool::{ContactTool, ToolPose};

/// A sphere placed in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldSphere {
    /// Centre, m.
    pub centre: Vec3,
    /// Radius, m.
    pub radius: f32,
    /// Part of the cutting edge.
    pub cutting: bool,
}

/// A box placed in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldBox {
    /// Centre, m.
    pub centre: Vec3,
    /// Box axes in world coordinates (columns, unit length).
    pub axes: Mat3,
    /// Half side lengths, m.
    pub half_extents: Vec3,
}

impl WorldBox {
    /// Box-frame coordinates of world point `x`.
    pub fn to_local(&self, x: Vec3) -> Vec3 {
        self.axes.transpose() * (x - self.centre)
    }

    /// World coordinates of box-frame point `l`.
    pub fn to_world(&self, l: Vec3) -> Vec3 {
        self.centre + self.axes * l
    }
}

/// The tool's primitives at one pose, with a bounding box for the broad phase.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlacedTool {
    /// Spheres in world coordinates, in the tool's order.
    pub spheres: Vec<WorldSphere>,
    /// Boxes in world coordinates, in the tool's order.
    pub boxes: Vec<WorldBox>,
    /// Lower corner of the axis-aligned bounds of all primitives, m.
    pub lo: Vec3,
    /// Upper corner of the axis-aligned bounds of all primitives, m.
    pub hi: Vec3,
}

impl PlacedTool {
    /// `tool` at `pose`.
    pub fn new(tool: &ContactTool, pose: &ToolPose) -> Self {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let spheres = tool
            .spheres
            .iter()
            .map(|s| {
                let c = pose.transform_point(s.centre);
                lo = lo.min(c - s.radius);
                hi = hi.max(c + s.radius);
                WorldSphere {
                    centre: c,
                    radius: s.radius,
                    cutting: s.cutting,
                }
            })
            .collect();
        let boxes = tool
            .boxes
            .iter()
            .map(|b| {
                let axes = Mat3::from_quat(pose.rotation * b.rotation);
                let centre = pose.transform_point(b.centre);
                // Half extent of the box along each world axis.
                let reach = axes.abs() * b.half_extents;
                lo = lo.min(centre - reach);
                hi = hi.max(centre + reach);
                WorldBox {
                    centre,
                    axes,
                    half_extents: b.half_extents,
                }
            })
            .collect();
        PlacedTool {
            spheres,
            boxes,
            lo,
            hi,
        }
    }

    /// Signed distance of the whole tool at `x` (minimum over primitives), m.
    pub fn distance(&self, x: Vec3) -> f32 {
        let s = self
            .spheres
            .iter()
            .map(|s| sphere_distance(x, s.centre, s.radius));
        let b = self
            .boxes
            .iter()
            .map(|b| box_distance(b.to_local(x), b.half_extents));
        s.chain(b).fold(f32::INFINITY, f32::min)
    }

    /// Signed distance of the cutting-edge spheres alone at `x`, m (∞ if none).
    pub fn edge_distance(&self, x: Vec3) -> f32 {
        self.spheres
            .iter()
            .filter(|s| s.cutting)
            .map(|s| sphere_distance(x, s.centre, s.radius))
            .fold(f32::INFINITY, f32::min)
    }
}

/// `d(x) = ‖x − c‖ − r` (PHYSICS.md §1.5).
pub fn sphere_distance(x: Vec3, centre: Vec3, radius: f32) -> f32 {
    (x - centre).length() - radius
}

/// Exact signed distance of a box with half extents `h` centred at the origin, at the
/// box-frame point `l`.
pub fn box_distance(l: Vec3, h: Vec3) -> f32 {
    let q = l.abs() - h;
    q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ToolBox, ToolSphere};
    use glam::Quat;

    #[test]
    fn box_distance_outside_inside_and_at_corners() {
        let h = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(box_distance(Vec3::ZERO, h), -1.0);
        assert_eq!(box_distance(Vec3::new(3.0, 0.0, 0.0), h), 2.0);
        assert_eq!(box_distance(Vec3::new(0.0, -1.5, 0.0), h), -0.5);
        let corner = box_distance(Vec3::new(2.0, 3.0, 3.0), h);
        assert!((corner - 2f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn placed_tool_follows_the_pose() {
        let tool = ContactTool {
            spheres: vec![ToolSphere {
                centre: Vec3::X,
                radius: 0.5,
                cutting: true,
            }],
            boxes: vec![ToolBox {
                centre: Vec3::new(0.0, 0.0, 2.0),
                rotation: Quat::IDENTITY,
                half_extents: Vec3::new(0.1, 0.2, 0.3),
            }],
            friction: 0.0,
        };
        let pose = ToolPose::new(
            Vec3::new(0.0, 0.0, 1.0),
            Quat::from_rotation_z(90f32.to_radians()),
        );
        let placed = PlacedTool::new(&tool, &pose);
        // Tool x axis maps onto world y.
        assert!((placed.spheres[0].centre - Vec3::new(0.0, 1.0, 1.0)).length() < 1e-6);
        assert!(placed.distance(Vec3::new(0.0, 1.0, 1.0)) < -0.49);
        assert!(placed.edge_distance(Vec3::new(0.0, 2.0, 1.0)) > 0.49);
        // The box (rotated 90° about z) reaches 0.2 m along world x at z = 3 m.
        assert!(placed.distance(Vec3::new(0.19, 0.0, 3.0)) < 0.0);
        assert!(placed.distance(Vec3::new(0.0, 0.15, 3.0)) > 0.0);
        assert!(placed.lo.z <= 0.5 + 1e-6 && placed.hi.z >= 3.3 - 1e-6);
    }
}
