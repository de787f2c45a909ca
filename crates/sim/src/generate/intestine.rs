//! A segment of small bowel: a thick-walled tube with a lumen, bent along a planar curve,
//! lying on a table (z ≥ 0), with a finer skin on the exact smooth tube surface.

use std::f64::consts::TAU;

use glam::{DVec2, DVec3, Vec3};

use super::hex_grid_tets;
use crate::mesh::{RawMesh, TriSurface};

/// Tets of the seed paper's intestine (PHYSICS.md §1.6), which the default resolution matches.
pub const PAPER_TETS: usize = 34_345;

/// Shape of the tube's centreline: a planar curve in the x-y plane made of circular arcs.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Centreline {
    /// One arc turning left by `turn` radians in total (0: straight, π: a U).
    Arc {
        /// Total turning angle, radians.
        turn: f32,
    },
    /// Two equal arcs turning left, then right, by `turn` radians each (an S).
    SCurve {
        /// Turning angle of each half, radians.
        turn: f32,
    },
}

/// Size, shape and resolution of the intestine segment; lengths in metres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct IntestineParams {
    /// Hexes around the circumference (at least 3).
    pub segments_around: u32,
    /// Hex layers through the wall (at least 1).
    pub layers_through_wall: u32,
    /// Hexes along the centreline (at least 1).
    pub segments_along: u32,
    /// Outer radius of the tube, m.
    pub outer_radius: f32,
    /// Wall thickness, m (less than the outer radius; the rest is the lumen).
    pub wall_thickness: f32,
    /// Length of the centreline, m.
    pub length: f32,
    /// Shape of the centreline.
    pub centreline: Centreline,
    /// Skin subdivisions per tet-boundary edge, around, along and through the end rings
    /// (2 gives 4× the tet boundary's triangle count).
    pub skin_refine: u32,
}

impl Default for IntestineParams {
    /// 32 around × 2 through the wall × 89 along × 6 = 34,176 tets (seed paper: 34,345),
    /// outer radius 1.5 cm, wall 4 mm, 30 cm along a gentle S.
    fn default() -> Self {
        Self {
            segments_around: 32,
            layers_through_wall: 2,
            segments_along: 89,
            outer_radius: 0.015,
            wall_thickness: 0.004,
            length: 0.30,
            centreline: Centreline::SCurve {
                turn: std::f32::consts::FRAC_PI_3,
            },
            skin_refine: 2,
        }
    }
}

impl IntestineParams {
    /// Default geometry with the resolution scaled (same cell aspect) to about `n` tets,
    /// for the benchmark series (≈34k, 140k, 550k, 1.1M).
    pub fn with_target_tets(n: usize) -> IntestineParams {
        let base = Self::default();
        let base_tets =
            6.0 * (base.segments_around * base.layers_through_wall * base.segments_along) as f64;
        let s = (n as f64 / base_tets).cbrt();
        let around = ((base.segments_around as f64 * s).round() as u32).max(3);
        let layers = ((base.layers_through_wall as f64 * s).round() as u32).max(1);
        // Along takes up the rounding of the other two, so the count lands near `n`.
        let along = ((n as f64 / (6.0 * around as f64 * layers as f64)).round() as u32).max(1);
        IntestineParams {
            segments_around: around,
            layers_through_wall: layers,
            segments_along: along,
            ..base
        }
    }

    /// Number of tets [`intestine`] generates for these parameters.
    pub fn tet_count(&self) -> usize {
        6 * self.segments_around as usize
            * self.layers_through_wall as usize
            * self.segments_along as usize
    }

    /// Inner (lumen) radius, m.
    pub fn inner_radius(&self) -> f32 {
        self.outer_radius - self.wall_thickness
    }

    /// Problems with these parameters, one sentence each (empty when they are usable).
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.segments_around < 3 || self.layers_through_wall < 1 || self.segments_along < 1 {
            out.push(format!(
                "intestine resolution {}×{}×{} (around × wall × along) needs at least 3×1×1",
                self.segments_around, self.layers_through_wall, self.segments_along
            ));
        }
        let lengths = [self.outer_radius, self.wall_thickness, self.length];
        if lengths.iter().any(|v| !v.is_finite() || *v <= 0.0) {
            out.push("intestine radius, wall thickness and length must be positive".into());
        } else if self.wall_thickness >= self.outer_radius {
            out.push(format!(
                "intestine wall thickness {} m leaves no lumen inside radius {} m",
                self.wall_thickness, self.outer_radius
            ));
        }
        let bend = Path::new(self).min_bend_radius();
        if bend.is_nan() || bend <= self.outer_radius as f64 {
            out.push(format!(
                "intestine centreline bends with radius {bend:.4} m, tighter than the tube \
                 radius {} m: the inner side of the bend folds over itself",
                self.outer_radius
            ));
        }
        out
    }
}

/// The intestine's tet mesh and its skin.
///
/// Tet nodes sit on circles of the exact tube (inner radius to outer radius, evenly through
/// the wall); the skin (outer surface, lumen surface facing into the lumen, and the two end
/// rings) is `skin_refine` times finer in each direction with every vertex on the smooth
/// surface, all triangles counter-clockwise seen from outside the wall. The centreline lies
/// at height `outer_radius`, so the tube rests on `z = 0`, and its x-y bounding box is
/// centred on the origin with the chord from start to end along +x. Unusable parameters
/// (see [`IntestineParams::problems`]) are reported in the mesh's warnings.
pub fn intestine(p: &IntestineParams) -> (RawMesh, TriSurface) {
    let path = Path::new(p);
    let (r_in, r_out) = (p.inner_radius() as f64, p.outer_radius as f64);
    let (na, nw, nl) = (
        p.segments_around as usize,
        p.layers_through_wall as usize,
        p.segments_along as usize,
    );
    let mut raw = hex_grid_tets([na, nw + 1, nl + 1], true, |i, j, k| {
        let phi = TAU * i as f64 / na as f64;
        let rho = r_in + (r_out - r_in) * j as f64 / nw.max(1) as f64;
        path.surface_point(phi, rho, p.length as f64 * k as f64 / nl.max(1) as f64)
    });
    raw.warnings.extend(p.problems());
    let skin = skin(p, &path);
    (raw, skin)
}

/// The skin: outer and inner surfaces plus the two end rings, one closed surface.
fn skin(p: &IntestineParams, path: &Path) -> TriSurface {
    let m = p.skin_refine.max(1) as usize;
    let a = m * p.segments_around.max(3) as usize;
    let s = m * p.segments_along.max(1) as usize + 1;
    let w = m * p.layers_through_wall.max(1) as usize + 1;
    let (r_in, r_out) = (p.inner_radius() as f64, p.outer_radius as f64);
    let len = p.length as f64;
    let phi = |i: usize| TAU * i as f64 / a as f64;
    let along = |k: usize| len * k as f64 / (s - 1) as f64;
    let rho = |ring: usize| r_in + (r_out - r_in) * ring as f64 / (w - 1) as f64;

    let mut positions = Vec::with_capacity(2 * a * s + 2 * a * (w - 2));
    for r in [r_out, r_in] {
        for k in 0..s {
            positions.extend((0..a).map(|i| path.surface_point(phi(i), r, along(k))));
        }
    }
    for k in [0, s - 1] {
        for ring in 1..w - 1 {
            positions.extend((0..a).map(|i| path.surface_point(phi(i), rho(ring), along(k))));
        }
    }

    let outer = |i: usize, k: usize| (i % a + a * k) as u32;
    let inner = |i: usize, k: usize| (a * s + i % a + a * k) as u32;
    // Ring `ring` (0 = lumen, w-1 = outside) of end `e` (0 = start, 1 = end).
    let cap = |e: usize, i: usize, ring: usize| {
        let k = e * (s - 1);
        if ring == 0 {
            inner(i, k)
        } else if ring == w - 1 {
            outer(i, k)
        } else {
            (2 * a * s + e * a * (w - 2) + i % a + a * (ring - 1)) as u32
        }
    };

    let mut triangles = Vec::with_capacity(4 * a * (s - 1) + 4 * a * (w - 1));
    // The frame (tangent, radial, around) is right-handed: quads stepping +around then
    // +along face outward (+radial); quads stepping +radial then +around face +tangent.
    for k in 0..s - 1 {
        for i in 0..a {
            let (q0, q1, q2, q3) = (
                outer(i, k),
                outer(i + 1, k),
                outer(i + 1, k + 1),
                outer(i, k + 1),
            );
            triangles.push([q0, q1, q2]);
            triangles.push([q0, q2, q3]);
            let (q0, q1, q2, q3) = (
                inner(i, k),
                inner(i + 1, k),
                inner(i + 1, k + 1),
                inner(i, k + 1),
            );
            triangles.push([q0, q2, q1]);
            triangles.push([q0, q3, q2]);
        }
    }
    for e in 0..2 {
        for ring in 0..w - 1 {
            for i in 0..a {
                let (q0, q1, q2, q3) = (
                    cap(e, i, ring),
                    cap(e, i, ring + 1),
                    cap(e, i + 1, ring + 1),
                    cap(e, i + 1, ring),
                );
                if e == 1 {
                    triangles.push([q0, q1, q2]);
                    triangles.push([q0, q2, q3]);
                } else {
                    triangles.push([q0, q2, q1]);
                    triangles.push([q0, q3, q2]);
                }
            }
        }
    }
    TriSurface {
        positions,
        triangles,
    }
}

/// The centreline as a function of arc length, placed in the scene.
struct Path {
    /// Arcs as (length, curvature), from the start.
    arcs: Vec<(f64, f64)>,
    /// Rotation (cos, sin) taking the raw curve's start-to-end chord onto +x.
    rot: DVec2,
    /// Translation applied after the rotation (centres the x-y bounds; lifts to z = R).
    offset: DVec3,
}

impl Path {
    fn new(p: &IntestineParams) -> Path {
        let len = p.length as f64;
        let arcs = match p.centreline {
            Centreline::Arc { turn } => vec![(len, turn as f64 / len)],
            Centreline::SCurve { turn } => {
                let k = 2.0 * turn as f64 / len;
                vec![(0.5 * len, k), (0.5 * len, -k)]
            }
        };
        let mut path = Path {
            arcs,
            rot: DVec2::X,
            offset: DVec3::ZERO,
        };
        let end = path.raw(len).0;
        if end.length() > 1e-12 && end.is_finite() {
            path.rot = DVec2::new(end.x, -end.y).normalize();
        }
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        const SAMPLES: usize = 512;
        for q in 0..=SAMPLES {
            let c = path.rot.rotate(path.raw(len * q as f64 / SAMPLES as f64).0);
            (lo, hi) = (lo.min(c), hi.max(c));
        }
        let centre = 0.5 * (lo + hi);
        path.offset = DVec3::new(-centre.x, -centre.y, p.outer_radius as f64);
        if !path.offset.is_finite() {
            path.offset = DVec3::ZERO;
        }
        path
    }

    /// Smallest radius of curvature along the centreline (infinite when straight).
    fn min_bend_radius(&self) -> f64 {
        self.arcs
            .iter()
            .map(|&(_, k)| 1.0 / k.abs())
            .fold(f64::INFINITY, f64::min)
    }

    /// Point and heading angle of the unplaced curve (starting at the origin along +x) at
    /// arc length `s`.
    fn raw(&self, s: f64) -> (DVec2, f64) {
        let (mut point, mut heading, mut left) = (DVec2::ZERO, 0.0f64, s);
        for (i, &(len, k)) in self.arcs.iter().enumerate() {
            let last = i + 1 == self.arcs.len();
            let ds = if last { left } else { left.min(len) };
            // Exact arc step: a chord of length 2 sin(kΔs/2)/k at the mean heading.
            let half = 0.5 * k * ds;
            let chord = if half.abs() < 1e-9 {
                ds
            } else {
                ds * half.sin() / half
            };
            point += chord * DVec2::from_angle(heading + half);
            heading += 2.0 * half;
            left -= ds;
            if left <= 0.0 {
                break;
            }
        }
        (point, heading)
    }

    /// Point at angle `phi` around the centreline (0: in-plane to the left, π/2: up) and
    /// distance `rho` from it, at arc length `s`.
    fn surface_point(&self, phi: f64, rho: f64, s: f64) -> Vec3 {
        let (c, heading) = self.raw(s);
        let c = self.rot.rotate(c);
        let t = self.rot.rotate(DVec2::from_angle(heading));
        let normal = DVec3::new(-t.y, t.x, 0.0);
        let p = DVec3::new(c.x, c.y, 0.0)
            + self.offset
            + rho * (phi.cos() * normal + phi.sin() * DVec3::Z);
        p.as_vec3()
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;
    use crate::generate::hex_grid::tests::assert_conforming;
    use crate::mesh::TetMesh;

    fn shell_volume(p: &IntestineParams) -> f64 {
        let (r_out, r_in) = (p.outer_radius as f64, p.inner_radius() as f64);
        std::f64::consts::PI * (r_out * r_out - r_in * r_in) * p.length as f64
    }

    #[test]
    fn default_matches_the_paper_and_the_tube() {
        let p = IntestineParams::default();
        assert!(p.problems().is_empty(), "{:?}", p.problems());
        let (raw, skin) = intestine(&p);
        assert!(raw.warnings.is_empty(), "{:?}", raw.warnings);
        let tets = raw.tets.len();
        assert_eq!(tets, p.tet_count());
        assert!(
            (tets as f64 - PAPER_TETS as f64).abs() / (PAPER_TETS as f64) < 0.01,
            "{tets} tets"
        );
        let boundary = assert_conforming(&raw);
        let (na, nw, nl) = (32, 2, 89);
        // Outer + inner (2 triangles per quad each) + two end rings.
        assert_eq!(boundary, 2 * (2 * na * nl) + 2 * (2 * na * nw));

        let (mesh, report) = TetMesh::from_raw(raw).unwrap();
        assert_eq!(
            report.reoriented_tets, 0,
            "generator must emit positive tets"
        );
        assert_eq!(mesh.boundary.len(), boundary);
        let rel = (mesh.total_rest_volume() - shell_volume(&p)).abs() / shell_volume(&p);
        assert!(rel < 0.03, "volume off by {rel}");

        // Lies on the table, centred in x-y, about 30 cm long.
        let (lo, hi) = mesh.rest_bounds();
        assert!(lo.z.abs() < 1e-6 && (hi.z - 0.03).abs() < 1e-6, "{lo} {hi}");
        assert!(
            (lo.x + hi.x).abs() < 1e-3 && (lo.y + hi.y).abs() < 1e-3,
            "{lo} {hi}"
        );
        assert!(hi.x - lo.x > 0.2 && hi.x - lo.x < 0.35, "{lo} {hi}");

        assert!(skin.triangles.len() >= 2 * boundary);
    }

    #[test]
    fn skin_is_closed_outward_and_on_the_smooth_tube() {
        let p = IntestineParams {
            segments_along: 20,
            ..IntestineParams::default()
        };
        let (_, skin) = intestine(&p);
        // Closed and consistently wound: every directed edge once, its reverse once.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &skin.triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(edges.values().all(|&c| c == 0));
        // Positive enclosed volume ⇒ outward; close to the analytic shell volume since the
        // skin is finer than the tets.
        let vol: f64 = skin
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| skin.positions[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let rel = (vol - shell_volume(&p)).abs() / shell_volume(&p);
        assert!(rel < 0.005, "skin volume {vol} off by {rel}");
        // Outer and inner skin rings lie on circles of the exact radius, in the plane
        // normal to the centreline.
        let path = Path::new(&p);
        let (a, rings) = (64, 41);
        for (half, r) in [(0, p.outer_radius), (1, p.inner_radius())] {
            for k in 0..rings {
                let s = p.length as f64 * k as f64 / (rings - 1) as f64;
                let c = path.surface_point(0.0, 0.0, s);
                let t = (path.surface_point(0.0, 0.0, s + 1e-4) - c).normalize();
                for i in 0..a {
                    let q = skin.positions[half * a * rings + k * a + i] - c;
                    assert!((q.length() - r).abs() < 1e-6, "{} vs {r}", q.length());
                    assert!(q.dot(t).abs() < 1e-5);
                }
            }
        }
        let start = path.surface_point(0.0, 0.0, 0.0);
        assert!((start.z - p.outer_radius).abs() < 1e-7);
    }

    #[test]
    fn target_series_lands_near_the_targets() {
        for n in [34_345, 140_000, 550_000, 1_100_000] {
            let p = IntestineParams::with_target_tets(n);
            let rel = (p.tet_count() as f64 - n as f64).abs() / n as f64;
            assert!(rel < 0.02, "{n}: {p:?} gives {}", p.tet_count());
            assert!(p.problems().is_empty());
        }
    }

    #[test]
    fn bad_parameters_warn_instead_of_panicking() {
        let p = IntestineParams {
            segments_around: 2,
            wall_thickness: 0.02,
            centreline: Centreline::Arc { turn: 100.0 },
            skin_refine: 0,
            ..IntestineParams::default()
        };
        let (raw, _) = intestine(&p);
        assert!(raw.tets.is_empty());
        assert!(raw.warnings.len() >= 3, "{:?}", raw.warnings);
    }
}
