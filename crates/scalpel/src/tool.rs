//! A validated tool in SI units and the contact primitives it gives the solver: cutting
//! spheres along the edge (arc-length spacing, tangent to the edge from inside) plus the
//! non-cutting body boxes.

use std::path::Path;

use glam::{Quat, Vec2, Vec3};
use incise_sim::contact::{ContactTool, ToolBox, ToolSphere};
use incise_sim::ron_file;
use parry3d::shape::Compound;

use crate::error::{FieldError, FileError};
use crate::ron_text;
use crate::tool_body::{compound, to_parry};
use crate::tool_spec::{SpherePlacement, ToolSpec};

/// Most cutting spheres a tool places along its edge (a very fine tissue mesh with
/// [`SpherePlacement::FromTissue`] is capped here, the spheres then spaced wider).
pub const MAX_EDGE_SPHERES: usize = 1024;

const MM: f32 = 1e-3;

/// The handle as a box in the tool frame, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handle {
    /// Length along x, m.
    pub length: f32,
    /// Width along z, m.
    pub width: f32,
    /// Thickness along y, m.
    pub thickness: f32,
    /// Centre of the front (blade-side) face, m.
    pub front: Vec3,
}

/// A scalpel ready for use: blade, edge, body and handle in the tool frame, SI units.
#[derive(Debug, Clone)]
pub struct Tool {
    name: String,
    source: String,
    outline: Vec<Vec2>,
    thickness: f32,
    edge: Vec<Vec2>,
    handle: Handle,
    placement: SpherePlacement,
    friction: f32,
    body: Vec<ToolBox>,
    pub(crate) body_shape: Compound,
    sharp: bool,
}

/// Read, check and convert a tool file (`config/tools/*.ron`).
pub fn load_tool(path: &Path) -> Result<Tool, FileError> {
    let text = ron_file::read(path)?;
    parse_tool(&text, path)
}

/// Parse, check and convert tool RON text; `path` names it in errors.
pub fn parse_tool(text: &str, path: &Path) -> Result<Tool, FileError> {
    let spec: ToolSpec = ron_file::parse(text, path)?;
    Tool::from_spec(&spec).map_err(|e| ron_text::value_error(text, path, e))
}

impl Tool {
    /// The tool a spec describes, converted from mm to m; the spec is validated first.
    pub fn from_spec(spec: &ToolSpec) -> Result<Tool, FieldError> {
        spec.validate()?;
        let v2 = |p: &[f32; 2]| Vec2::new(p[0], p[1]) * MM;
        let v3 = |p: &[f32; 3]| Vec3::from_array(*p) * MM;
        let placement = match spec.spheres {
            SpherePlacement::Fixed { count, radius } => SpherePlacement::Fixed {
                count,
                radius: radius * MM,
            },
            other => other,
        };
        let body: Vec<ToolBox> = spec
            .body
            .iter()
            .map(|b| ToolBox {
                centre: v3(&b.centre),
                rotation: Quat::from_array(b.rotation).normalize(),
                half_extents: v3(&b.half_extents),
            })
            .collect();
        let body_shape = compound(&body);
        Ok(Tool {
            name: spec.name.clone(),
            source: spec.source.clone(),
            outline: spec.outline.iter().map(v2).collect(),
            thickness: spec.thickness * MM,
            edge: spec.edge.iter().map(v2).collect(),
            handle: Handle {
                length: spec.handle.length * MM,
                width: spec.handle.width * MM,
                thickness: spec.handle.thickness * MM,
                front: v3(&spec.handle.front),
            },
            placement,
            friction: spec.friction,
            body,
            body_shape,
            sharp: true,
        })
    }

    /// The tool's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where its dimensions come from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Blade outline in the x–z plane, m.
    pub fn outline(&self) -> &[Vec2] {
        &self.outline
    }

    /// Blade thickness, m.
    pub fn thickness(&self) -> f32 {
        self.thickness
    }

    /// Cutting edge polyline in the x–z plane, m, tip first.
    pub fn edge(&self) -> &[Vec2] {
        &self.edge
    }

    /// Length of the cutting edge polyline, m.
    pub fn edge_length(&self) -> f32 {
        self.edge.windows(2).map(|w| (w[1] - w[0]).length()).sum()
    }

    /// The handle box, m.
    pub fn handle(&self) -> Handle {
        self.handle
    }

    /// Sphere placement rule (a `Fixed` radius here is in m).
    pub fn placement(&self) -> SpherePlacement {
        self.placement
    }

    /// Positional friction coefficient.
    pub fn friction(&self) -> f32 {
        self.friction
    }

    /// The non-cutting body boxes, m.
    pub fn body(&self) -> &[ToolBox] {
        &self.body
    }

    /// Whether the edge cuts (false for [`Tool::dull`]).
    pub fn is_sharp(&self) -> bool {
        self.sharp
    }

    /// The same tool with a dull edge: its edge spheres push but never cut.
    pub fn dull(&self) -> Tool {
        Tool {
            sharp: false,
            ..self.clone()
        }
    }

    /// Cutting-sphere radius (m) and count for a tissue of the given mean tet edge length.
    ///
    /// # Panics
    /// If the placement is `FromTissue` and `mean_edge_length_m` is not a positive finite
    /// length (a mesh's mean edge length always is).
    pub fn edge_spheres_for(&self, mean_edge_length_m: f32) -> (f32, usize) {
        match self.placement {
            SpherePlacement::Fixed { count, radius } => (radius, count as usize),
            SpherePlacement::FromTissue {
                radius_factor,
                spacing_factor,
            } => {
                assert!(
                    mean_edge_length_m.is_finite() && mean_edge_length_m > 0.0,
                    "mean tissue edge length must be a positive length in m, got {mean_edge_length_m}"
                );
                let radius = radius_factor * mean_edge_length_m;
                let spacing = spacing_factor * radius;
                let count = (self.edge_length() / spacing).ceil() as usize + 1;
                (radius, count.min(MAX_EDGE_SPHERES))
            }
        }
    }

    /// The solver's view of the tool for a tissue whose mean tet edge length is
    /// `mean_edge_length_m` (used only by `FromTissue` placement): cutting spheres evenly
    /// along the edge by arc length (both ends included; one sphere sits mid-edge), each
    /// centred one radius inside the blade along the edge's in-plane normal so that it is
    /// tangent to the edge line from inside, then the body boxes (never cutting). A dull
    /// tool's edge spheres push but do not cut.
    ///
    /// # Panics
    /// As [`Tool::edge_spheres_for`].
    pub fn contact_tool(&self, mean_edge_length_m: f32) -> ContactTool {
        let (radius, count) = self.edge_spheres_for(mean_edge_length_m);
        let spheres = edge_points(&self.edge, count)
            .into_iter()
            .map(|(p, normal)| {
                let inward = normal * self.inward_sign();
                let c = p + inward * radius;
                ToolSphere {
                    centre: Vec3::new(c.x, 0.0, c.y),
                    radius,
                    cutting: true,
                }
            })
            .collect();
        let tool = ContactTool {
            spheres,
            boxes: self.body.clone(),
            friction: self.friction,
        };
        if self.sharp { tool } else { tool.dulled() }
    }

    /// +1 if the left normal of the edge (tangent rotated +90° in x–z) points into the
    /// blade outline, −1 otherwise: decided at the middle of the longest edge segment.
    fn inward_sign(&self) -> f32 {
        let (a, b) = self
            .edge
            .windows(2)
            .map(|w| (w[0], w[1]))
            .max_by(|x, y| (x.1 - x.0).length().total_cmp(&(y.1 - y.0).length()))
            .expect("validated: the edge has at least 2 points");
        let t = (b - a).normalize();
        let probe = (a + b) * 0.5 + t.perp() * (self.thickness.max(1e-5) * 0.5);
        if point_in_polygon(probe, &self.outline) {
            1.0
        } else {
            -1.0
        }
    }
}

/// `count` points evenly spaced by arc length along `edge` (both ends; the midpoint when
/// `count` is 1), each with the unit left normal (tangent rotated +90°) there; at a
/// polyline vertex the normal averages the two sides' normals.
fn edge_points(edge: &[Vec2], count: usize) -> Vec<(Vec2, Vec2)> {
    let seg_len: Vec<f32> = edge.windows(2).map(|w| (w[1] - w[0]).length()).collect();
    let total: f32 = seg_len.iter().sum();
    let seg_normal = |i: usize| (edge[i + 1] - edge[i]).normalize().perp();
    let targets: Vec<f32> = if count == 1 {
        vec![0.5 * total]
    } else {
        (0..count)
            .map(|k| total * k as f32 / (count - 1) as f32)
            .collect()
    };
    let mut out = Vec::with_capacity(count);
    let mut seg = 0usize;
    let mut seg_start = 0.0f32;
    for (k, &s) in targets.iter().enumerate() {
        while seg + 1 < seg_len.len() && s > seg_start + seg_len[seg] {
            seg_start += seg_len[seg];
            seg += 1;
        }
        let last = count > 1 && k == count - 1;
        let local = if last {
            seg_len[seg]
        } else {
            (s - seg_start).clamp(0.0, seg_len[seg])
        };
        let p = if last {
            edge[edge.len() - 1]
        } else {
            edge[seg] + (edge[seg + 1] - edge[seg]) * (local / seg_len[seg])
        };
        let mut n = seg_normal(seg);
        // At a vertex (within float noise), blend with the neighbouring segment.
        let eps = 1e-6 * total;
        if local <= eps && seg > 0 {
            n = (n + seg_normal(seg - 1)).normalize_or(n);
        } else if local >= seg_len[seg] - eps && seg + 1 < seg_len.len() {
            n = (n + seg_normal(seg + 1)).normalize_or(n);
        }
        out.push((p, n));
    }
    out
}

/// Even-odd rule point-in-polygon test.
fn point_in_polygon(p: Vec2, poly: &[Vec2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

impl Tool {
    /// The non-cutting body (blade flat and handle boxes) as a parry3d compound in the
    /// tool frame, m.
    pub fn body_shape(&self) -> &Compound {
        &self.body_shape
    }

    /// Signed distance (m) from tool-frame point `p` to the body: positive outside,
    /// negative inside; the least of the boxes' signed distances, as the solver takes it.
    ///
    /// (A parry compound projects onto its nearest part, so a point inside the handle
    /// but just outside the overlapping blade flat would come out positive.)
    pub fn body_distance(&self, p: Vec3) -> f32 {
        let p = to_parry(p);
        self.body_shape
            .shapes()
            .iter()
            .map(|(pose, shape)| shape.distance_to_point(pose, p, false))
            .fold(f32::INFINITY, f32::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_points_are_evenly_spaced_and_hit_both_ends() {
        let edge = [Vec2::ZERO, Vec2::new(3.0, 0.0), Vec2::new(3.0, 4.0)];
        let pts = edge_points(&edge, 8);
        assert_eq!(pts.len(), 8);
        assert_eq!(pts[0].0, Vec2::ZERO);
        assert_eq!(pts[7].0, Vec2::new(3.0, 4.0));
        // Total length 7, spacing 1 along the polyline.
        assert!((pts[3].0 - Vec2::new(3.0, 0.0)).length() < 1e-5);
        assert!((pts[5].0 - Vec2::new(3.0, 2.0)).length() < 1e-5);
        // Left normal of +x is +z (the y of Vec2); at the corner it is blended.
        assert!((pts[1].1 - Vec2::Y).length() < 1e-6);
        assert!((pts[3].1 - Vec2::new(-1.0, 1.0).normalize()).length() < 1e-5);
        assert!((pts[6].1 - Vec2::new(-1.0, 0.0)).length() < 1e-6);
        let one = edge_points(&edge, 1);
        assert!((one[0].0 - Vec2::new(3.0, 0.5)).length() < 1e-5);
    }

    #[test]
    fn point_in_polygon_square() {
        let sq = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        assert!(point_in_polygon(Vec2::splat(0.5), &sq));
        assert!(!point_in_polygon(Vec2::new(1.5, 0.5), &sq));
    }
}
