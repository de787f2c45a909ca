//! Projection of one node onto the tool's surface for one substep (PHYSICS.md §1.5:
//! `C = d(x) ≥ 0` along ∇d, infinitely stiff), continuous over the substep and with
//! positional Coulomb friction. The WGSL twin is `gpu/shaders/contact.wgsl`.

use glam::Vec3;

use super::sdf::{PlacedTool, WorldBox, WorldSphere, box_distance};

/// Distance within which a node counts as lying on the tool's surface at the start of
/// a substep (where the last projection left it, give or take rounding), m.
pub const ON_SURFACE: f32 = 1e-6;

/// What the contact did to one node in one substep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeContact {
    /// The node's position after the projection, m.
    pub x: Vec3,
    /// The node touched the tool (it was moved).
    pub moved: bool,
    /// The node ended within the cut reach of a cutting sphere.
    pub near_edge: bool,
}

/// Project node `x` (which was at `x_prev` when the substep began) out of the tool, which
/// moved from `from` to `to` during the substep.
///
/// Continuous: a node whose path relative to a primitive entered it during the substep
/// is put back on the side it came from, even if it ended beyond the primitive, so a
/// thin blade moving several of its own widths per substep cannot tunnel through a
/// node. Friction: the node's tangential motion relative to the tool is removed up to
/// `friction ×` the normal correction (static), beyond that scaled down (kinetic),
/// as in Macklin et al. 2014 §6.1. `reach` is the cut zone's reach (m) or `None`.
pub fn project_node(
    x_prev: Vec3,
    x: Vec3,
    from: &PlacedTool,
    to: &PlacedTool,
    friction: f32,
    reach: Option<f32>,
) -> NodeContact {
    let margin = reach.unwrap_or(0.0).max(0.0);
    let seg_lo = x_prev.min(x);
    let seg_hi = x_prev.max(x);
    let lo = from.lo.min(to.lo) - margin;
    let hi = from.hi.max(to.hi) + margin;
    if seg_hi.cmplt(lo).any() || seg_lo.cmpgt(hi).any() {
        return NodeContact {
            x,
            moved: false,
            near_edge: false,
        };
    }
    let x_in = x;
    let mut p = x;
    for (s0, s1) in from.spheres.iter().zip(&to.spheres) {
        p = push_out_of_sphere(x_prev, p, s0, s1);
    }
    for (b0, b1) in from.boxes.iter().zip(&to.boxes) {
        p = push_out_of_box(x_prev, p, b0, b1);
    }
    let correction = p - x_in;
    let depth = correction.length();
    if depth > 0.0 && friction > 0.0 {
        p = apply_friction(x_prev, p, correction / depth, depth, friction, from, to);
    }
    NodeContact {
        x: p,
        moved: p != x_in,
        near_edge: reach.is_some_and(|r| to.edge_distance(p) < r),
    }
}

/// Sphere contact, continuous in the sphere's frame: the relative path runs from
/// `a = x_prev − c0` to `b = x − c1`.
///
/// A node whose path enters the sphere during the substep goes back to the surface
/// along the normal where it entered, even if it ended beyond the sphere (no
/// tunnelling). A node that starts the substep on the surface (where the last substep
/// left it, within [`ON_SURFACE`]) or inside stays where it sits on a cutting sphere
/// (the edge bites: tissue does not flow round a blade's edge, it is stressed until the
/// criterion releases it), and leaves a non-cutting sphere by the shortest way, so it
/// slides round it with friction, unless that is past the centre from where it
/// started. The tolerance makes the choice independent of rounding (CPU and GPU agree).
fn push_out_of_sphere(x_prev: Vec3, x: Vec3, s0: &WorldSphere, s1: &WorldSphere) -> Vec3 {
    let r = s1.radius;
    let a = x_prev - s0.centre;
    let b = x - s1.centre;
    let n = if a.length() > r + ON_SURFACE {
        // First time t ∈ [0, 1] with |a + t (b − a)| = r, if any.
        let e = b - a;
        let ee = e.length_squared();
        let ae = a.dot(e);
        let disc = ae * ae - ee * (a.length_squared() - r * r);
        if ee <= 0.0 || disc < 0.0 {
            return x;
        }
        let t = (-ae - disc.sqrt()) / ee;
        if !(0.0..=1.0).contains(&t) {
            return x;
        }
        (a + e * t).normalize_or(Vec3::Z)
    } else if b.length_squared() < r * r {
        let start = a.try_normalize().unwrap_or(Vec3::Z);
        match b.try_normalize() {
            Some(nb) if !s1.cutting && nb.dot(start) > 0.0 => nb,
            _ => start,
        }
    } else {
        return x;
    };
    s1.centre + n * r
}

/// Box contact, continuous in the box's frame (slab test of the relative path): a node
/// whose path enters the box goes back onto the face it came through; one that starts
/// on a face (within [`ON_SURFACE`]) or inside goes out through the face nearest to
/// where it was, unless it is already past that face.
fn push_out_of_box(x_prev: Vec3, x: Vec3, b0: &WorldBox, b1: &WorldBox) -> Vec3 {
    let h = b1.half_extents;
    let l0 = b0.to_local(x_prev);
    let mut l1 = b1.to_local(x);
    if box_distance(l0, h) > ON_SURFACE {
        let e = l1 - l0;
        let (mut t_in, mut t_out) = (f32::NEG_INFINITY, f32::INFINITY);
        let mut axis = 0;
        for i in 0..3 {
            if e[i].abs() < 1e-12 {
                if l0[i].abs() > h[i] {
                    return x;
                }
                continue;
            }
            let (mut t1, mut t2) = ((-h[i] - l0[i]) / e[i], (h[i] - l0[i]) / e[i]);
            if t1 > t2 {
                std::mem::swap(&mut t1, &mut t2);
            }
            if t1 > t_in {
                t_in = t1;
                axis = i;
            }
            t_out = t_out.min(t2);
        }
        if t_in > t_out || !(0.0..=1.0).contains(&t_in) {
            return x;
        }
        l1[axis] = if e[axis] > 0.0 { -h[axis] } else { h[axis] };
    } else {
        let (axis, side) = nearest_face(l0, h);
        if l1[axis] * side >= h[axis] {
            return x;
        }
        l1[axis] = side * h[axis];
    }
    b1.to_world(l1)
}

/// The face of a box (half extents `h`) nearest to the box-frame point `l`: axis and
/// side (±1).
fn nearest_face(l: Vec3, h: Vec3) -> (usize, f32) {
    let q = l.abs() - h;
    let axis = if q.x >= q.y && q.x >= q.z {
        0
    } else if q.y >= q.z {
        1
    } else {
        2
    };
    (axis, if l[axis] >= 0.0 { 1.0 } else { -1.0 })
}

/// Positional Coulomb friction against the tool's own motion at the contact point.
fn apply_friction(
    x_prev: Vec3,
    x: Vec3,
    normal: Vec3,
    depth: f32,
    friction: f32,
    from: &PlacedTool,
    to: &PlacedTool,
) -> Vec3 {
    let tool_motion = rigid_motion_at(x, from, to);
    let rel = (x - x_prev) - tool_motion;
    let tangential = rel - normal * rel.dot(normal);
    let slip = tangential.length();
    if slip <= 0.0 {
        return x;
    }
    let limit = friction * depth;
    if slip <= limit {
        x - tangential
    } else {
        x - tangential * (limit / slip)
    }
}

/// How far the tool's material point now at `x` moved during the substep (the tool is
/// rigid, so any two of its primitives give its motion; spheres first, else boxes).
fn rigid_motion_at(x: Vec3, from: &PlacedTool, to: &PlacedTool) -> Vec3 {
    if let (Some(b0), Some(b1)) = (from.boxes.first(), to.boxes.first()) {
        return x - b0.to_world(b1.to_local(x));
    }
    match (from.spheres.as_slice(), to.spheres.as_slice()) {
        ([a0, .., z0], [a1, .., z1]) if (a1.centre - z1.centre).length() > 0.0 => {
            // Rotation about the axis through the first and last sphere is not seen by
            // two points; edges are long and thin, so the error is their spin, ≈ 0.
            let t = (x - a1.centre).dot(z1.centre - a1.centre)
                / (z1.centre - a1.centre).length_squared();
            (a1.centre - a0.centre).lerp(z1.centre - z0.centre, t.clamp(0.0, 1.0))
        }
        ([s0, ..], [s1, ..]) => s1.centre - s0.centre,
        _ => Vec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactTool, ToolPose, ToolSphere};

    fn ball(r: f32) -> ContactTool {
        ContactTool {
            spheres: vec![ToolSphere {
                centre: Vec3::ZERO,
                radius: r,
                cutting: true,
            }],
            boxes: vec![],
            friction: 0.0,
        }
    }

    fn at(tool: &ContactTool, p: Vec3) -> PlacedTool {
        PlacedTool::new(tool, &ToolPose::new(p, glam::Quat::IDENTITY))
    }

    #[test]
    fn a_node_inside_is_pushed_to_the_surface() {
        let t = ball(0.01);
        let placed = at(&t, Vec3::ZERO);
        let c = project_node(
            Vec3::new(0.005, 0.0, 0.0),
            Vec3::new(0.005, 0.0, 0.0),
            &placed,
            &placed,
            0.0,
            Some(0.001),
        );
        assert!((c.x - Vec3::new(0.01, 0.0, 0.0)).length() < 1e-7);
        assert!(c.moved && c.near_edge);
    }

    #[test]
    fn a_sphere_jumping_over_a_node_pushes_it_ahead() {
        // The sphere moves 10 radii in one substep across a resting node.
        let t = ball(0.001);
        let from = at(&t, Vec3::new(-0.005, 0.0, 0.0));
        let to = at(&t, Vec3::new(0.005, 0.0, 0.0));
        let node = Vec3::new(0.0, 0.0002, 0.0);
        let c = project_node(node, node, &from, &to, 0.0, None);
        assert!(c.x.x > 0.005, "node left behind the sphere: {:?}", c.x);
        assert!((c.x - to.spheres[0].centre).length() >= 0.001 - 1e-6);
    }
}
