//! The planned incision drawn on the tissue like a surgical marker line, and moving with
//! it: every drawn point of the plan is embedded once in a tet of the rest mesh by
//! barycentric coordinates, so each frame its position follows the tet's nodes and its
//! normal follows the tet's deformation gradient (`F⁻ᵀ n`). Definitions: docs/scoring.md.

use glam::{Mat3, Vec3};
use incise_sim::TetMesh;
use incise_sim::mesh::{closest_point_on_triangle, shape_matrix};
use incise_xr::SurfaceLine;

/// Spacing of the drawn points along the plan, m (about; the plan's own samples, every
/// k-th).
pub const DECAL_SPACING: f64 = 0.001;

/// Width of the drawn line, m: a fine surgical skin marker's.
pub const DECAL_WIDTH: f32 = 0.001;

/// Colour of the line, linear RGB: gentian violet, the ink of surgical skin markers
/// (sRGB #6A1B9A).
pub const DECAL_COLOUR: [f32; 3] = [0.144, 0.011, 0.323];

/// How far inside the surface, as a fraction of the mesh's mean edge length, a point is
/// moved to find the tet under it.
const NUDGE: f32 = 0.02;

/// Barycentric slack under which a point still counts as inside a tet.
const INSIDE_EPS: f32 = 1e-5;

/// A point of a planned line on the rest surface, m, and the outward normal there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkPoint {
    /// The point, m.
    pub point: Vec3,
    /// The outward surface normal.
    pub normal: Vec3,
}

/// One drawn point: its tet and barycentric weights, and what is needed to map its rest
/// normal with the tet's deformation.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Anchor {
    /// The tet.
    tet: u32,
    /// The tet's four nodes.
    nodes: [u32; 4],
    /// Barycentric weights of the point in the tet (sum 1; slightly outside 0..1 when the
    /// point lies just outside the tet).
    bary: [f32; 4],
    /// Inverse rest shape matrix of the tet.
    dm_inv: Mat3,
    /// Outward surface normal at rest.
    normal: Vec3,
}

/// The plan as a line on the deforming tissue (docs/scoring.md, "The plan on the
/// tissue").
#[derive(Debug, Clone, PartialEq)]
pub struct PlanDecal {
    anchors: Vec<Anchor>,
    /// Points that lay outside every tet and were embedded in the nearest boundary tet.
    pub outside: usize,
}

impl PlanDecal {
    /// Embed a planned line in `mesh`: `marks` sampled every `spacing` (m) along it on
    /// the rest surface; every k-th (about [`DECAL_SPACING`] apart, the last always) goes
    /// into the tet that contains it moved slightly inward along its normal, else into the
    /// tet of the nearest boundary face.
    pub fn new(marks: &[MarkPoint], spacing: f64, mesh: &TetMesh) -> PlanDecal {
        let step = ((DECAL_SPACING / spacing.max(1e-12)).round() as usize).max(1);
        let last = marks.len().saturating_sub(1);
        let mut picked: Vec<usize> = (0..marks.len()).step_by(step).collect();
        if picked.last().is_some_and(|&i| i != last) {
            picked.push(last);
        }
        let nudge = NUDGE * mesh.mean_edge_length();
        let mut outside = 0;
        let anchors = picked
            .iter()
            .map(|&i| {
                let MarkPoint {
                    point: p,
                    normal: n,
                } = marks[i];
                let (tet, inside) = match containing_tet(mesh, p - n * nudge) {
                    Some(t) => (t, true),
                    None => (nearest_boundary_tet(mesh, p), false),
                };
                outside += usize::from(!inside);
                let nodes = mesh.tets[tet];
                Anchor {
                    tet: tet as u32,
                    nodes,
                    bary: barycentric(mesh, tet, p),
                    dm_inv: mesh.dm_inv[tet],
                    normal: n,
                }
            })
            .collect();
        PlanDecal { anchors, outside }
    }

    /// Number of drawn points.
    pub fn len(&self) -> usize {
        self.anchors.len()
    }

    /// Whether there is nothing to draw.
    pub fn is_empty(&self) -> bool {
        self.anchors.is_empty()
    }

    /// The decal on a body whose nodes are at `positions`, [`DECAL_WIDTH`] wide in
    /// [`DECAL_COLOUR`]: each point is its tet's nodes weighted by its barycentric
    /// coordinates, each normal the rest normal mapped by the tet's deformation gradient
    /// `F` as `F⁻ᵀ n` (computed as cof(F)·n with the sign of det F), normalised; a
    /// degenerate tet keeps the rest normal. One entry per drawn point, in order: a point
    /// whose tet names a node past the end of `positions`, or that comes out non-finite,
    /// is a gap (a NaN point with a zero normal), where the renderer splits the line.
    pub fn line(&self, positions: &[Vec3]) -> SurfaceLine {
        self.build(positions, |_| true)
    }

    /// [`PlanDecal::line`] with a gap wherever the point's tet was cut away
    /// (`live[t]` false): the ink goes with the tissue, and what is left of the line is
    /// the part of the plan not cut yet. Tets past the end of `live` count as live.
    pub fn line_uncut(&self, positions: &[Vec3], live: &[bool]) -> SurfaceLine {
        self.build(positions, |t| live.get(t).copied().unwrap_or(true))
    }

    fn build(&self, positions: &[Vec3], keep: impl Fn(usize) -> bool) -> SurfaceLine {
        let mut out = SurfaceLine {
            points: Vec::with_capacity(self.anchors.len()),
            normals: Vec::with_capacity(self.anchors.len()),
            width: DECAL_WIDTH,
            colour: DECAL_COLOUR,
        };
        for a in &self.anchors {
            let (p, n) = match a.deformed(positions) {
                Some(pn) if keep(a.tet as usize) => pn,
                _ => (Vec3::NAN, Vec3::ZERO),
            };
            out.points.push(p);
            out.normals.push(n);
        }
        out
    }
}

impl Anchor {
    /// Position and unit normal for node positions `positions`; `None` when a node is
    /// missing or the result is not finite.
    fn deformed(&self, positions: &[Vec3]) -> Option<(Vec3, Vec3)> {
        if self.nodes.iter().any(|&i| i as usize >= positions.len()) {
            return None;
        }
        let x = self.nodes.map(|i| positions[i as usize]);
        let p: Vec3 = (0..4).map(|c| self.bary[c] * x[c]).sum();
        let f = shape_matrix(x[0], x[1], x[2], x[3]) * self.dm_inv;
        let cof = Mat3::from_cols(
            f.y_axis.cross(f.z_axis),
            f.z_axis.cross(f.x_axis),
            f.x_axis.cross(f.y_axis),
        );
        let m = cof * self.normal * f.determinant().signum();
        let n = m.try_normalize().unwrap_or(self.normal);
        (p.is_finite() && n.is_finite()).then_some((p, n))
    }
}

/// Barycentric weights of `p` in tet `t` of `mesh` (rest), from the tet's inverse shape
/// matrix.
fn barycentric(mesh: &TetMesh, t: usize, p: Vec3) -> [f32; 4] {
    let x0 = mesh.rest_positions[mesh.tets[t][0] as usize];
    let l = mesh.dm_inv[t] * (p - x0);
    [1.0 - l.x - l.y - l.z, l.x, l.y, l.z]
}

/// The tet containing `p` at rest (the one it is deepest inside, where faces meet).
fn containing_tet(mesh: &TetMesh, p: Vec3) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (t, tet) in mesh.tets.iter().enumerate() {
        let x = tet.map(|i| mesh.rest_positions[i as usize]);
        let (lo, hi) = (
            x[0].min(x[1]).min(x[2].min(x[3])),
            x[0].max(x[1]).max(x[2].max(x[3])),
        );
        if p.cmplt(lo).any() || p.cmpgt(hi).any() {
            continue;
        }
        let inside = barycentric(mesh, t, p)
            .into_iter()
            .fold(f32::INFINITY, f32::min);
        if inside >= -INSIDE_EPS && best.is_none_or(|b| inside > b.1) {
            best = Some((t, inside));
        }
    }
    best.map(|b| b.0)
}

/// The tet of the boundary face nearest to `p` at rest (tet 0 for a mesh without
/// boundary, which a valid mesh never is).
fn nearest_boundary_tet(mesh: &TetMesh, p: Vec3) -> usize {
    let mut best = (0usize, f32::INFINITY);
    for &(t, f) in &mesh.boundary {
        let [a, b, c] = mesh
            .face_nodes(t as usize, f as usize)
            .map(|i| mesh.rest_positions[i as usize]);
        let d = (closest_point_on_triangle(p, a, b, c) - p).length_squared();
        if d < best.1 {
            best = (t as usize, d);
        }
    }
    best.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exercise::{Plan, RestSurface};
    use incise_sim::generate;

    /// A 4 × 2 × 1 cm slab of 2.5 mm cells, and a plan along its top: a bent line so
    /// the decal has a corner.
    fn slab_and_plan() -> (TetMesh, Plan) {
        let raw = generate::block(
            Vec3::ZERO,
            Vec3::new(0.04, 0.02, 0.01),
            glam::UVec3::new(16, 8, 4),
        );
        let mesh = TetMesh::from_raw(raw).unwrap().0;
        let surface = RestSurface::of_mesh(&mesh);
        let pts = [
            Vec3::new(0.005, 0.006, 0.01),
            Vec3::new(0.02, 0.011, 0.01),
            Vec3::new(0.035, 0.0093, 0.01),
        ];
        let plan = Plan::new(&pts, &surface, 0.001).unwrap();
        (mesh, plan)
    }

    #[test]
    fn at_rest_the_line_is_the_plan_every_millimetre() {
        let (mesh, plan) = slab_and_plan();
        let decal = plan.decal(&mesh);
        assert_eq!(decal.outside, 0);
        let line = decal.line(&mesh.rest_positions);
        assert_eq!(line.points.len(), decal.len());
        // The first and last samples, the rest about 1 mm apart.
        let first = plan.samples[0].point.as_vec3();
        let last = plan.samples[plan.samples.len() - 1].point.as_vec3();
        assert!((line.points[0] - first).length() < 1e-6);
        assert!((line.points[line.points.len() - 1] - last).length() < 1e-6);
        for w in line.points.windows(2) {
            let gap = (w[1] - w[0]).length() as f64;
            assert!(gap <= DECAL_SPACING * 1.01, "gap {gap}");
        }
        // Every drawn point is a plan sample, with its normal (up, on the slab's top).
        for (p, n) in line.points.iter().zip(&line.normals) {
            let nearest = plan
                .samples
                .iter()
                .map(|s| (s.point.as_vec3() - *p).length())
                .fold(f32::INFINITY, f32::min);
            assert!(nearest < 1e-6, "{p} is {nearest} m from the plan");
            assert!((*n - Vec3::Z).length() < 1e-6, "normal {n}");
        }
    }

    #[test]
    fn an_affine_deformation_moves_points_and_normals_exactly() {
        let (mesh, plan) = slab_and_plan();
        let decal = plan.decal(&mesh);
        let rest = decal.line(&mesh.rest_positions);
        // Stretch, shear and a rotation, then a shift: x ↦ A x + b.
        let a = Mat3::from_rotation_z(0.4)
            * Mat3::from_cols(
                Vec3::new(1.3, 0.0, 0.2),
                Vec3::new(0.25, 0.8, 0.0),
                Vec3::new(0.0, -0.15, 1.1),
            );
        let b = Vec3::new(0.01, -0.02, 0.005);
        let moved: Vec<Vec3> = mesh.rest_positions.iter().map(|&x| a * x + b).collect();
        let line = decal.line(&moved);
        assert_eq!(line.points.len(), rest.points.len());
        let cof = a.inverse().transpose();
        for i in 0..line.points.len() {
            let want = a * rest.points[i] + b;
            assert!(
                (line.points[i] - want).length() < 1e-6,
                "point {i}: {} vs {want}",
                line.points[i]
            );
            let n = (cof * rest.normals[i]).normalize();
            assert!(
                (line.normals[i] - n).length() < 1e-5,
                "normal {i}: {} vs {n}",
                line.normals[i]
            );
            // Still a normal of the moved surface: orthogonal to moved tangents.
            assert!((a * Vec3::X).dot(line.normals[i]).abs() < 1e-5);
        }
    }

    #[test]
    fn a_point_off_the_mesh_goes_into_the_nearest_boundary_tet() {
        let (mesh, _) = slab_and_plan();
        let p = Vec3::new(0.021, 0.012, 0.0105);
        assert!(containing_tet(&mesh, p).is_none());
        let t = nearest_boundary_tet(&mesh, p);
        let bary = barycentric(&mesh, t, p);
        let at_rest: Vec3 = (0..4)
            .map(|c| bary[c] * mesh.rest_positions[mesh.tets[t][c] as usize])
            .sum();
        assert!((at_rest - p).length() < 1e-6, "{at_rest} vs {p}");
        let centre: Vec3 = mesh.tets[t]
            .iter()
            .map(|&i| mesh.rest_positions[i as usize])
            .sum::<Vec3>()
            / 4.0;
        assert!(
            centre.z > 0.0075,
            "tet centre {centre} is not under the top"
        );
    }

    /// Whether entry `i` of `line` is a gap (where the renderer splits the line).
    fn gap(line: &SurfaceLine, i: usize) -> bool {
        !line.points[i].is_finite() && line.normals[i] == Vec3::ZERO
    }

    #[test]
    fn short_or_broken_positions_are_gaps_without_panicking() {
        let (mesh, plan) = slab_and_plan();
        let decal = plan.decal(&mesh);
        let short = decal.line(&[]);
        assert_eq!(short.points.len(), decal.len());
        assert!((0..decal.len()).all(|i| gap(&short, i)));
        let nan = vec![Vec3::NAN; mesh.node_count()];
        let broken = decal.line(&nan);
        assert!((0..decal.len()).all(|i| gap(&broken, i)));
        let rest = decal.line(&mesh.rest_positions);
        assert!((0..decal.len()).all(|i| !gap(&rest, i)));
    }

    #[test]
    fn tets_cut_away_take_their_part_of_the_line() {
        let (mesh, plan) = slab_and_plan();
        let decal = plan.decal(&mesh);
        // Cut away the tets under the middle third of the line.
        let n = decal.len();
        let mut live = vec![true; mesh.tet_count()];
        for a in &decal.anchors[n / 3..2 * n / 3] {
            live[a.tet as usize] = false;
        }
        let line = decal.line_uncut(&mesh.rest_positions, &live);
        assert_eq!(line.points.len(), n);
        for i in 0..n {
            let cut = !live[decal.anchors[i].tet as usize];
            assert_eq!(gap(&line, i), cut, "point {i}");
        }
        assert!((n / 3..2 * n / 3).all(|i| gap(&line, i)));
        assert!(!gap(&line, 0) && !gap(&line, n - 1));
        // Nothing cut: the whole line.
        assert_eq!(
            decal.line_uncut(&mesh.rest_positions, &[]),
            decal.line(&mesh.rest_positions)
        );
    }
}
