//! The tool file format (`config/tools/*.ron`): a scalpel as drawn, lengths in mm in the
//! tool frame (see the crate docs), checked field by field.

use serde::{Deserialize, Serialize};

use crate::error::FieldError;

/// Default positional friction coefficient of a steel blade on wet soft tissue.
///
/// Needle-insertion friction measured on soft tissue ranges 0.122–0.341 and falls with
/// contact pressure (ASME MSEC 2021, paper V001T03A008, "friction coefficient … needle
/// insertion"); a lubricated, polished blade pressed hard sits at the low end.
pub const DEFAULT_FRICTION: f32 = 0.15;

/// A tool as written in its RON file (mm, tool frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolSpec {
    /// Short name, e.g. `"scalpel_10"`.
    pub name: String,
    /// Where the dimensions come from (or that they are nominal).
    pub source: String,
    /// Blade outline polygon in the x–z plane, mm (either winding, not closed).
    pub outline: Vec<[f32; 2]>,
    /// Blade thickness along y, mm.
    pub thickness: f32,
    /// The cutting edge as a polyline in the x–z plane, mm, from the tip toward the heel.
    pub edge: Vec<[f32; 2]>,
    /// The handle, for rendering.
    pub handle: HandleSpec,
    /// How the cutting spheres are sized and spaced along the edge.
    pub spheres: SpherePlacement,
    /// Positional friction coefficient (dimensionless); [`DEFAULT_FRICTION`] if absent.
    #[serde(default = "default_friction")]
    pub friction: f32,
    /// The coarse non-cutting body (blade flat, handle) as boxes, mm.
    pub body: Vec<BodyBoxSpec>,
}

fn default_friction() -> f32 {
    DEFAULT_FRICTION
}

/// The handle as a box: its front face centred at `front`, extending along +x.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandleSpec {
    /// Length along x, mm.
    pub length: f32,
    /// Width along z, mm.
    pub width: f32,
    /// Thickness along y, mm.
    pub thickness: f32,
    /// Centre of the handle's front (blade-side) face in the tool frame, mm.
    pub front: [f32; 3],
}

/// How many cutting spheres, and how large.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SpherePlacement {
    /// `count` spheres of `radius` mm, whatever the tissue.
    Fixed {
        /// Number of spheres (≥ 1).
        count: u32,
        /// Radius, mm.
        radius: f32,
    },
    /// Sized to the tissue mesh: radius = `radius_factor` × mean tet edge length, spacing
    /// = `spacing_factor` × radius, count = ⌈edge length / spacing⌉ + 1.
    FromTissue {
        /// Radius over the tissue's mean edge length.
        radius_factor: f32,
        /// Sphere spacing over the radius.
        spacing_factor: f32,
    },
}

/// One box of the non-cutting body, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyBoxSpec {
    /// Centre in the tool frame, mm.
    pub centre: [f32; 3],
    /// Half side lengths along the box axes, mm.
    pub half_extents: [f32; 3],
    /// Box orientation in the tool frame, quaternion `(x, y, z, w)`; identity if absent.
    #[serde(default = "identity")]
    pub rotation: [f32; 4],
}

fn identity() -> [f32; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

fn positive(field: &str, v: f32, unit: &str) -> Result<(), FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(
            field,
            format!("must be a positive finite {unit}, got {v}"),
        ))
    }
}

fn finite(field: &str, v: &[f32]) -> Result<(), FieldError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(FieldError::new(field, format!("must be finite, got {v:?}")))
    }
}

impl ToolSpec {
    /// Ok, or the first field that cannot be used and why.
    pub fn validate(&self) -> Result<(), FieldError> {
        if self.name.trim().is_empty() {
            return Err(FieldError::new("name", "must not be empty"));
        }
        if self.outline.len() < 3 {
            return Err(FieldError::new(
                "outline",
                format!(
                    "needs at least 3 points (x, z) in mm, got {}",
                    self.outline.len()
                ),
            ));
        }
        for (i, p) in self.outline.iter().enumerate() {
            finite(&format!("outline[{i}]"), p)?;
        }
        check_simple_polygon(&self.outline)?;
        positive("thickness", self.thickness, "length in mm")?;
        if self.edge.is_empty() {
            return Err(FieldError::new(
                "edge",
                "is empty: the cutting edge needs at least 2 points (x, z) in mm",
            ));
        }
        if self.edge.len() < 2 {
            return Err(FieldError::new(
                "edge",
                "needs at least 2 points (x, z) in mm, got 1",
            ));
        }
        for (i, p) in self.edge.iter().enumerate() {
            finite(&format!("edge[{i}]"), p)?;
        }
        for i in 1..self.edge.len() {
            let [ax, az] = self.edge[i - 1];
            let [bx, bz] = self.edge[i];
            if ax == bx && az == bz {
                return Err(FieldError::new(
                    format!("edge[{i}]"),
                    "repeats the previous point (zero-length edge segment)",
                ));
            }
        }
        positive("handle.length", self.handle.length, "length in mm")?;
        positive("handle.width", self.handle.width, "length in mm")?;
        positive("handle.thickness", self.handle.thickness, "length in mm")?;
        finite("handle.front", &self.handle.front)?;
        match self.spheres {
            SpherePlacement::Fixed { count, radius } => {
                if count == 0 {
                    return Err(FieldError::new(
                        "spheres.count",
                        "must be at least 1 (a blade with no cutting spheres cannot cut)",
                    ));
                }
                if count as usize > crate::MAX_EDGE_SPHERES {
                    return Err(FieldError::new(
                        "spheres.count",
                        format!("must be at most {}, got {count}", crate::MAX_EDGE_SPHERES),
                    ));
                }
                positive("spheres.radius", radius, "length in mm")?;
            }
            SpherePlacement::FromTissue {
                radius_factor,
                spacing_factor,
            } => {
                positive("spheres.radius_factor", radius_factor, "ratio")?;
                positive("spheres.spacing_factor", spacing_factor, "ratio")?;
            }
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(FieldError::new(
                "friction",
                format!("must be a finite coefficient >= 0, got {}", self.friction),
            ));
        }
        if self.body.is_empty() {
            return Err(FieldError::new(
                "body",
                "must list at least one box (the handle, at least)",
            ));
        }
        for (i, b) in self.body.iter().enumerate() {
            finite(&format!("body[{i}].centre"), &b.centre)?;
            for (axis, &h) in ["x", "y", "z"].iter().zip(&b.half_extents) {
                positive(&format!("body[{i}].half_extents.{axis}"), h, "length in mm")?;
            }
            finite(&format!("body[{i}].rotation"), &b.rotation)?;
            let len = b.rotation.iter().map(|x| x * x).sum::<f32>().sqrt();
            if (len - 1.0).abs() > 1e-3 {
                return Err(FieldError::new(
                    format!("body[{i}].rotation"),
                    format!("not a unit quaternion (length {len})"),
                ));
            }
        }
        Ok(())
    }
}

/// Ok if the closed polygon has non-zero area and no two non-adjacent sides cross.
fn check_simple_polygon(p: &[[f32; 2]]) -> Result<(), FieldError> {
    let n = p.len();
    let area2: f64 = (0..n)
        .map(|i| {
            let [ax, az] = p[i];
            let [bx, bz] = p[(i + 1) % n];
            ax as f64 * bz as f64 - bx as f64 * az as f64
        })
        .sum();
    if area2.abs() < 1e-12 {
        return Err(FieldError::new("outline", "has zero area"));
    }
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if adjacent {
                continue;
            }
            if segments_cross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]) {
                return Err(FieldError::new(
                    "outline",
                    format!(
                        "is not a simple polygon: side {i}–{} crosses side {j}–{}",
                        (i + 1) % n,
                        (j + 1) % n
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn segments_cross(a: [f32; 2], b: [f32; 2], c: [f32; 2], d: [f32; 2]) -> bool {
    let orient = |p: [f32; 2], q: [f32; 2], r: [f32; 2]| {
        let v = (q[0] as f64 - p[0] as f64) * (r[1] as f64 - p[1] as f64)
            - (q[1] as f64 - p[1] as f64) * (r[0] as f64 - p[0] as f64);
        v.partial_cmp(&0.0).map_or(0, |o| o as i32)
    };
    let (o1, o2, o3, o4) = (
        orient(a, b, c),
        orient(a, b, d),
        orient(c, d, a),
        orient(c, d, b),
    );
    o1 * o2 < 0 && o3 * o4 < 0
}
