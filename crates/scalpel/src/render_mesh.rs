//! The tool as a closed triangle mesh for the renderer: the blade outline extruded by its
//! thickness, and the handle box, in the tool frame (m), outward-facing triangles.

use glam::{Vec2, Vec3};

use crate::tool::Tool;
use crate::triangulate::{signed_area, triangulate};

impl Tool {
    /// Vertices (tool frame, m) and counter-clockwise-outward triangles of two closed
    /// shells: the blade (outline extruded to `y = ±thickness/2`) and the handle box.
    pub fn render_mesh(&self) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut verts = Vec::new();
        let mut tris = Vec::new();
        extrude(self.outline(), self.thickness(), &mut verts, &mut tris);
        let h = self.handle();
        let centre = h.front + Vec3::new(0.5 * h.length, 0.0, 0.0);
        let half = Vec3::new(0.5 * h.length, 0.5 * h.thickness, 0.5 * h.width);
        push_box(centre, half, &mut verts, &mut tris);
        (verts, tris)
    }
}

/// The polygon (x, z) extruded over `y ∈ [−t/2, t/2]`.
fn extrude(outline: &[Vec2], t: f32, verts: &mut Vec<Vec3>, tris: &mut Vec<[u32; 3]>) {
    let mut poly = outline.to_vec();
    if signed_area(&poly) < 0.0 {
        poly.reverse();
    }
    let base = verts.len() as u32;
    let n = poly.len() as u32;
    verts.extend(poly.iter().map(|p| Vec3::new(p.x, -0.5 * t, p.y)));
    verts.extend(poly.iter().map(|p| Vec3::new(p.x, 0.5 * t, p.y)));
    // Counter-clockwise in (x, z) faces −y: the y = −t/2 cap as is, the +t/2 cap flipped.
    for [a, b, c] in triangulate(&poly) {
        tris.push([base + a, base + b, base + c]);
        tris.push([base + n + a, base + n + c, base + n + b]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        let (a, b, a_top, b_top) = (base + i, base + j, base + n + i, base + n + j);
        tris.push([a, b_top, b]);
        tris.push([a, a_top, b_top]);
    }
}

/// An axis-aligned box.
fn push_box(c: Vec3, h: Vec3, verts: &mut Vec<Vec3>, tris: &mut Vec<[u32; 3]>) {
    let base = verts.len() as u32;
    // Corner k has sign bit 0 → x, 1 → y, 2 → z (set: +).
    for k in 0..8u32 {
        let s = |bit: u32| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
        verts.push(c + h * Vec3::new(s(0), s(1), s(2)));
    }
    const FACES: [[u32; 4]; 6] = [
        [0, 4, 6, 2], // −x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // −y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // −z
        [4, 5, 7, 6], // +z
    ];
    for [a, b, c, d] in FACES {
        tris.push([base + a, base + b, base + c]);
        tris.push([base + a, base + c, base + d]);
    }
}
