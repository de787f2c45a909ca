//! The planned incision on the organ: the exercise's polyline projected onto the rest
//! surface of the tet mesh and sampled densely, each sample with the surface's outward
//! normal, so any point of the body can be placed relative to the plan (lateral distance,
//! depth, position along it). All in rest (material) coordinates: the tissue's
//! deformation during the attempt does not move the plan.

use glam::{DVec3, Vec3};
use incise_sim::TetMesh;

use crate::pictures::plan_decal::{MarkPoint, PlanDecal};

/// Largest spacing of the plan samples, m.
const SAMPLE_SPACING: f64 = 0.0005;

/// The organ's rest surface: the tet mesh's boundary triangles with outward normals.
pub struct RestSurface {
    triangles: Vec<[DVec3; 3]>,
    normals: Vec<DVec3>,
}

impl RestSurface {
    /// The boundary of `mesh` at rest.
    pub fn of_mesh(mesh: &TetMesh) -> RestSurface {
        let x = |i: u32| mesh.rest_positions[i as usize].as_dvec3();
        let mut triangles = Vec::with_capacity(mesh.boundary.len());
        let mut normals = Vec::with_capacity(mesh.boundary.len());
        for &(t, f) in &mesh.boundary {
            let [a, b, c] = mesh.face_nodes(t as usize, f as usize).map(x);
            let tet = mesh.tets[t as usize];
            let centroid = tet.iter().map(|&i| x(i)).sum::<DVec3>() / 4.0;
            let mut n = (b - a).cross(c - a).normalize_or_zero();
            if n.dot(a - centroid) < 0.0 {
                n = -n;
            }
            triangles.push([a, b, c]);
            normals.push(n);
        }
        RestSurface { triangles, normals }
    }

    /// The closest surface point to `p`, its distance and the outward normal there;
    /// `None` for a mesh without boundary.
    pub fn project(&self, p: DVec3) -> Option<(DVec3, f64, DVec3)> {
        let mut best: Option<(DVec3, f64, DVec3)> = None;
        for (tri, n) in self.triangles.iter().zip(&self.normals) {
            let q = closest_on_triangle(p, tri);
            let d = (q - p).length();
            if best.is_none_or(|b| d < b.1) {
                best = Some((q, d, *n));
            }
        }
        best
    }
}

/// Closest point of triangle `t` to `p` (incise-sim's, in f32: millimetre scoring
/// does not need more).
fn closest_on_triangle(p: DVec3, t: &[DVec3; 3]) -> DVec3 {
    let [a, b, c] = t.map(|v| v.as_vec3());
    incise_sim::mesh::closest_point_on_triangle(p.as_vec3(), a, b, c).as_dvec3()
}

/// One sample of the plan.
#[derive(Debug, Clone, Copy)]
pub struct PlanSample {
    /// Arc length from the plan's start, m.
    pub s: f64,
    /// The point on the rest surface, m.
    pub point: DVec3,
    /// Outward surface normal there.
    pub normal: DVec3,
}

/// Where a point lies relative to the plan.
#[derive(Debug, Clone, Copy)]
pub struct PlanCoords {
    /// Index of the nearest plan sample (in the surface's tangent plane).
    pub sample: usize,
    /// Distance from the plan in the tangent plane, m.
    pub lateral: f64,
    /// Depth below the surface at that sample (along the inward normal), m.
    pub depth: f64,
}

/// The planned incision, projected onto the surface and sampled.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The exercise's points projected onto the surface, m.
    pub points: Vec<DVec3>,
    /// Dense samples along the projected polyline.
    pub samples: Vec<PlanSample>,
    /// Length of the projected polyline, m.
    pub length: f64,
}

/// Why a plan point could not be put on the surface: its index and distance.
#[derive(Debug, Clone, Copy)]
pub struct OffSurface {
    /// Index of the point in the exercise's `plan`.
    pub index: usize,
    /// Its distance from the surface, m (infinite without a surface).
    pub distance: f64,
}

impl Plan {
    /// The plan drawn on `mesh` like a marker line (its samples embedded in the rest
    /// tets, see [`PlanDecal`]).
    pub fn decal(&self, mesh: &TetMesh) -> PlanDecal {
        let marks: Vec<MarkPoint> = self
            .samples
            .iter()
            .map(|s| MarkPoint {
                point: s.point.as_vec3(),
                normal: s.normal.as_vec3(),
            })
            .collect();
        PlanDecal::new(&marks, self.spacing(), mesh)
    }

    /// Project `points` onto `surface` (refusing any farther than `tolerance`) and sample
    /// the polyline through them at ≤ 0.5 mm, each sample projected again for its normal.
    pub fn new(points: &[Vec3], surface: &RestSurface, tolerance: f64) -> Result<Plan, OffSurface> {
        let mut projected = Vec::with_capacity(points.len());
        for (index, p) in points.iter().enumerate() {
            match surface.project(p.as_dvec3()) {
                Some((q, d, _)) if d <= tolerance => projected.push(q),
                found => {
                    return Err(OffSurface {
                        index,
                        distance: found.map_or(f64::INFINITY, |f| f.1),
                    });
                }
            }
        }
        let mut samples = Vec::new();
        let mut s0 = 0.0;
        for (k, leg) in projected.windows(2).enumerate() {
            let len = (leg[1] - leg[0]).length();
            let n = ((len / SAMPLE_SPACING).ceil() as usize).max(1);
            let first = if k == 0 { 0 } else { 1 };
            for i in first..=n {
                let u = i as f64 / n as f64;
                let p = leg[0].lerp(leg[1], u);
                let (point, _, normal) = surface.project(p).unwrap_or((p, 0.0, DVec3::Z));
                samples.push(PlanSample {
                    s: s0 + u * len,
                    point,
                    normal,
                });
            }
            s0 += len;
        }
        Ok(Plan {
            points: projected,
            samples,
            length: s0,
        })
    }

    /// Spacing of the samples, m.
    pub fn spacing(&self) -> f64 {
        self.length / (self.samples.len().max(2) - 1) as f64
    }

    /// Place `x` relative to the plan: nearest sample in the tangent plane, lateral
    /// distance and depth below the surface there.
    pub fn locate(&self, x: DVec3) -> PlanCoords {
        let mut best = PlanCoords {
            sample: 0,
            lateral: f64::INFINITY,
            depth: 0.0,
        };
        for (i, smp) in self.samples.iter().enumerate() {
            let v = x - smp.point;
            let along_normal = v.dot(smp.normal);
            let lateral = (v - smp.normal * along_normal).length();
            if lateral < best.lateral {
                best = PlanCoords {
                    sample: i,
                    lateral,
                    depth: -along_normal,
                };
            }
        }
        best
    }
}

/// Call `f` for every sample within `window` arc length of sample `centre`.
pub(super) fn for_window(plan: &Plan, centre: usize, window: f64, mut f: impl FnMut(usize)) {
    let s = plan.samples[centre].s;
    let lo = plan.samples[..centre]
        .iter()
        .rposition(|p| s - p.s > window)
        .map_or(0, |i| i + 1);
    let hi = plan.samples[centre..]
        .iter()
        .position(|p| p.s - s > window)
        .map_or(plan.samples.len(), |i| centre + i);
    (lo..hi).for_each(&mut f);
}

#[cfg(test)]
mod tests {
    use super::*;
    use incise_sim::generate;

    fn slab() -> TetMesh {
        let raw = generate::block(
            Vec3::ZERO,
            Vec3::new(0.04, 0.02, 0.01),
            glam::UVec3::new(8, 4, 2),
        );
        TetMesh::from_raw(raw).unwrap().0
    }

    #[test]
    fn plan_on_the_top_is_projected_and_sampled_with_upward_normals() {
        let surface = RestSurface::of_mesh(&slab());
        let pts = [Vec3::new(0.01, 0.01, 0.0105), Vec3::new(0.03, 0.01, 0.0098)];
        let plan = Plan::new(&pts, &surface, 0.002).unwrap();
        assert!((plan.length - 0.02).abs() < 1e-9, "{}", plan.length);
        assert!(plan.spacing() <= SAMPLE_SPACING + 1e-12);
        for s in &plan.samples {
            assert!(
                (s.point.z - 0.01).abs() < 1e-9 && s.normal.z > 0.99,
                "{s:?}"
            );
        }
        let c = plan.locate(DVec3::new(0.02, 0.013, 0.007));
        assert!(
            (c.lateral - 0.003).abs() < 1e-6 && (c.depth - 0.003).abs() < 1e-6,
            "{c:?}"
        );
    }

    #[test]
    fn point_off_the_surface_is_refused_with_its_index_and_distance() {
        let surface = RestSurface::of_mesh(&slab());
        let pts = [Vec3::new(0.01, 0.01, 0.01), Vec3::new(0.03, 0.01, 0.02)];
        let e = Plan::new(&pts, &surface, 0.002).unwrap_err();
        assert_eq!(e.index, 1);
        assert!((e.distance - 0.01).abs() < 1e-6, "{}", e.distance);
    }
}
