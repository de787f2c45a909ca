//! Surface lines as ribbons: each [`SurfaceLine`] becomes a band of triangles lying in the
//! tissue surface, built on the host every frame from the deformed points the app gives.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::frame::SurfaceLine;

/// Height of a ribbon above the surface, as a fraction of its width. The band's edges and
/// the chords between samples dip below a curved surface by about (w/2)²/2R and L²/8R
/// (tens of µm for a 2 mm band on a 15 mm radius), and the line's points, interpolated in
/// tets, stray from the skin triangles by as much. A quarter of the width (0.5 mm for a
/// 2 mm band) clears that with margin, so the skin never pokes through (no z-fighting),
/// and stays small beside the band itself, so the line does not read as floating.
pub(crate) const LIFT_PER_WIDTH: f32 = 0.25;

/// One ribbon vertex (`surface_line.wgsl`): position, unit surface normal, colour.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub(crate) struct LineVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub colour: [f32; 3],
}

/// A drawable point: lifted centre, half-width side vector, unit normal.
#[derive(Clone, Copy)]
struct Station {
    centre: Vec3,
    side: Vec3,
    normal: Vec3,
}

/// Append the triangles (a list, six vertices per segment) of every line to `out`.
///
/// At point i the tangent is the sum of the unit directions to its usable neighbours, the
/// side is `normalize(normal × tangent) · width/2`, and the centre is lifted by
/// [`LIFT_PER_WIDTH`] · width along the normal. A point is skipped, splitting the ribbon,
/// when its position or normal is not finite, its normal is zero, or its side is undefined
/// (no distinct neighbour, or the tangent along the normal). A line whose width is not a
/// positive finite number or whose colour is not finite is skipped whole; points beyond
/// the shorter of `points` and `normals` are ignored.
pub(crate) fn build(lines: &[SurfaceLine], out: &mut Vec<LineVertex>) {
    for line in lines {
        let usable_width = line.width.is_finite() && line.width > 0.0;
        if !usable_width || !line.colour.iter().all(|c| c.is_finite()) {
            continue;
        }
        let n = line.points.len().min(line.normals.len());
        let normal = |i: usize| -> Option<Vec3> {
            let p = line.points[i];
            let m = line.normals[i].normalize_or_zero();
            (p.is_finite() && m != Vec3::ZERO).then_some(m)
        };
        let normals: Vec<Option<Vec3>> = (0..n).map(normal).collect();
        let stations: Vec<Option<Station>> = (0..n)
            .map(|i| {
                let m = normals[i]?;
                let p = line.points[i];
                let towards = |j: usize| (line.points[j] - p).normalize_or_zero();
                let mut tangent = Vec3::ZERO;
                if i > 0 && normals[i - 1].is_some() {
                    tangent -= towards(i - 1);
                }
                if i + 1 < n && normals[i + 1].is_some() {
                    tangent += towards(i + 1);
                }
                let side = m.cross(tangent).normalize_or_zero();
                (side != Vec3::ZERO).then(|| Station {
                    centre: p + m * (LIFT_PER_WIDTH * line.width),
                    side: side * (0.5 * line.width),
                    normal: m,
                })
            })
            .collect();
        for pair in stations.windows(2) {
            let [Some(a), Some(b)] = [pair[0], pair[1]] else {
                continue;
            };
            let v = |s: &Station, sign: f32| LineVertex {
                position: (s.centre + s.side * sign).to_array(),
                normal: s.normal.to_array(),
                colour: line.colour,
            };
            let (al, ar, bl, br) = (v(&a, 1.0), v(&a, -1.0), v(&b, 1.0), v(&b, -1.0));
            out.extend_from_slice(&[al, ar, bl, ar, br, bl]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight(n: usize, width: f32) -> SurfaceLine {
        SurfaceLine {
            points: (0..n)
                .map(|i| Vec3::new(i as f32 * 0.01, 0.0, 0.0))
                .collect(),
            normals: vec![Vec3::Z * 3.0; n],
            width,
            colour: [0.1, 0.2, 0.9],
        }
    }

    fn built(lines: &[SurfaceLine]) -> Vec<LineVertex> {
        let mut out = Vec::new();
        build(lines, &mut out);
        out
    }

    #[test]
    fn a_straight_line_is_a_flat_band_of_its_width_lifted_along_the_normal() {
        let v = built(&[straight(5, 0.004)]);
        assert_eq!(v.len(), 4 * 6);
        for x in &v {
            let [px, py, pz] = x.position;
            assert!((0.0..=0.04 + 1e-6).contains(&px), "{px}");
            assert!((py.abs() - 0.002).abs() < 1e-7, "half width: {py}");
            assert!((pz - LIFT_PER_WIDTH * 0.004).abs() < 1e-7, "lift: {pz}");
            assert_eq!(x.normal, [0.0, 0.0, 1.0], "normals are unit");
            assert_eq!(x.colour, [0.1, 0.2, 0.9]);
        }
        // Each segment covers its full length on both sides.
        let xs: Vec<f32> = v[..6].iter().map(|x| x.position[0]).collect();
        assert_eq!(xs.iter().cloned().fold(f32::MAX, f32::min), 0.0);
        assert!((xs.iter().cloned().fold(f32::MIN, f32::max) - 0.01).abs() < 1e-7);
    }

    #[test]
    fn the_band_turns_with_the_surface_normal() {
        // A line along x on a wall facing +y: the band spans z, lifted along +y.
        let mut l = straight(3, 0.002);
        l.normals = vec![Vec3::Y; 3];
        for x in built(&[l]) {
            assert!((x.position[1] - LIFT_PER_WIDTH * 0.002).abs() < 1e-7);
            assert!((x.position[2].abs() - 0.001).abs() < 1e-7);
        }
    }

    #[test]
    fn degenerate_points_split_the_ribbon() {
        // Points 0..7: 3 has a zero normal, 5 a NaN position: segments 0-1, 1-2 and 6-7.
        let mut l = straight(8, 0.002);
        l.normals[3] = Vec3::ZERO;
        l.points[5] = Vec3::new(f32::NAN, 0.0, 0.0);
        let v = built(&[l]);
        assert_eq!(v.len(), 3 * 6);
        for x in &v {
            let px = x.position[0];
            assert!(
                px <= 0.02 + 1e-7 || px >= 0.06 - 1e-7,
                "a segment spans a gap: {px}"
            );
        }
        // Infinite normals and a repeated lone point (no tangent) are skipped too.
        let mut l = straight(4, 0.002);
        l.normals[1] = Vec3::new(f32::INFINITY, 0.0, 1.0);
        assert_eq!(built(&[l]).len(), 6);
        let mut l = straight(2, 0.002);
        l.points[1] = l.points[0];
        assert!(built(&[l]).is_empty());
        // A tangent along the normal has no side.
        let mut l = straight(2, 0.002);
        l.normals = vec![Vec3::X; 2];
        assert!(built(&[l]).is_empty());
    }

    #[test]
    fn bad_widths_colours_and_short_lists_draw_nothing_or_the_common_prefix() {
        for w in [0.0, -0.002, f32::NAN, f32::INFINITY] {
            assert!(built(&[straight(4, w)]).is_empty(), "width {w}");
        }
        let mut l = straight(4, 0.002);
        l.colour[1] = f32::NAN;
        assert!(built(&[l]).is_empty());
        assert!(built(&[straight(1, 0.002)]).is_empty());
        let mut l = straight(5, 0.002);
        l.normals.truncate(3);
        assert_eq!(built(&[l]).len(), 2 * 6);
        // Several lines: their triangles one after the other.
        assert_eq!(
            built(&[straight(3, 0.002), straight(4, 0.002)]).len(),
            5 * 6
        );
    }
}
