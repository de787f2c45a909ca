//! The blade and the partial plane C it sweeps between two poses (PHYSICS.md §2.4).

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// A pose of the blade's cutting edge: the segment from `heel` to `tip`, m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BladePose {
    /// Back end of the cutting edge.
    pub heel: DVec3,
    /// Front end of the cutting edge.
    pub tip: DVec3,
}

impl BladePose {
    /// The pose translated by `d`.
    pub fn translated(self, d: DVec3) -> BladePose {
        BladePose {
            heel: self.heel + d,
            tip: self.tip + d,
        }
    }

    /// Whether both ends are finite.
    pub fn is_finite(&self) -> bool {
        self.heel.is_finite() && self.tip.is_finite()
    }
}

/// The partial plane C swept by the cutting edge from one pose to the next: the quad
/// (previous heel, previous tip, current tip, current heel), flattened onto its mean plane
/// (exact when the blade moves within its own plane, as a scalpel does).
#[derive(Debug, Clone, PartialEq)]
pub struct SweptRegion {
    origin: DVec3,
    normal: DVec3,
    u: DVec3,
    v: DVec3,
    /// Corners in plane coordinates, in order around the quad.
    corners: [DVec2; 4],
    /// Largest corner distance from the origin (a length scale for tolerances).
    size: f64,
}

impl SweptRegion {
    /// The region swept from `from` to `to`; `None` when it has (almost) no area.
    pub fn new(from: BladePose, to: BladePose) -> Option<SweptRegion> {
        if !(from.is_finite() && to.is_finite()) {
            return None;
        }
        let p = [from.heel, from.tip, to.tip, to.heel];
        let origin = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        let size = p.iter().map(|q| (*q - origin).length()).fold(0.0, f64::max);
        // Quad normal from the cross product of its diagonals (twice the vector area).
        let n = (p[2] - p[0]).cross(p[3] - p[1]);
        if size <= 0.0 || n.length() < 1e-9 * size * size {
            return None;
        }
        let normal = n.normalize();
        let u = (p[1] - p[0])
            .reject_from_normalized(normal)
            .try_normalize()
            .or_else(|| (p[3] - p[0]).reject_from_normalized(normal).try_normalize())?;
        let v = normal.cross(u);
        let corners = p.map(|q| DVec2::new((q - origin).dot(u), (q - origin).dot(v)));
        Some(SweptRegion {
            origin,
            normal,
            u,
            v,
            corners,
            size,
        })
    }

    /// Unit normal of the plane.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// A length scale of the region (its circumradius about the centre), m.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Signed distance of `p` from the plane.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        (p - self.origin).dot(self.normal)
    }

    /// Plane coordinates of the projection of `p`.
    pub fn project(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// The point of the plane with plane coordinates `q`.
    pub fn lift(&self, q: DVec2) -> DVec3 {
        self.origin + self.u * q.x + self.v * q.y
    }

    /// Whether plane point `q` lies in the region or within `tol` of its boundary.
    pub fn contains(&self, q: DVec2, tol: f64) -> bool {
        self.winding_inside(q) || self.closest_on_boundary(q).0 <= tol
    }

    /// Whether `p` lies within `plane_tol` of the plane and its projection in the region
    /// (within `tol`).
    pub fn contains_point(&self, p: DVec3, plane_tol: f64, tol: f64) -> bool {
        self.signed_distance(p).abs() <= plane_tol && self.contains(self.project(p), tol)
    }

    /// Distance from plane point `q` to the region's boundary B, and the nearest point of B.
    pub fn closest_on_boundary(&self, q: DVec2) -> (f64, DVec2) {
        let mut best = (f64::INFINITY, q);
        for k in 0..4 {
            let (a, b) = (self.corners[k], self.corners[(k + 1) % 4]);
            let ab = b - a;
            let len2 = ab.length_squared();
            let s = if len2 > 0.0 {
                ((q - a).dot(ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let c = a + ab * s;
            let d = (q - c).length();
            if d < best.0 {
                best = (d, c);
            }
        }
        best
    }

    /// Axis-aligned bounds of the region, m.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.corners
            .iter()
            .map(|c| self.lift(*c))
            .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            })
    }

    /// Even-odd test against the (possibly non-convex) quad.
    fn winding_inside(&self, q: DVec2) -> bool {
        let mut inside = false;
        for k in 0..4 {
            let (a, b) = (self.corners[k], self.corners[(k + 1) % 4]);
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertical_blade(x: f64) -> BladePose {
        BladePose {
            heel: DVec3::new(x, 0.0, -1.0),
            tip: DVec3::new(x, 0.0, 1.0),
        }
    }

    #[test]
    fn sweep_along_x_is_the_y_zero_plane_strip() {
        let c = SweptRegion::new(vertical_blade(0.0), vertical_blade(2.0)).unwrap();
        assert!((c.normal().y.abs() - 1.0).abs() < 1e-12);
        assert!(c.contains_point(DVec3::new(1.0, 0.0, 0.5), 1e-9, 1e-9));
        assert!(!c.contains_point(DVec3::new(2.5, 0.0, 0.0), 1e-9, 1e-9));
        assert!(!c.contains_point(DVec3::new(1.0, 0.1, 0.0), 1e-9, 1e-9));
        let (d, b) = c.closest_on_boundary(c.project(DVec3::new(2.3, 0.0, 0.2)));
        assert!((d - 0.3).abs() < 1e-12);
        assert!((c.lift(b) - DVec3::new(2.0, 0.0, 0.2)).length() < 1e-12);
        assert!(c.signed_distance(DVec3::new(0.0, 0.25, 0.0)).abs() - 0.25 < 1e-12);
    }

    #[test]
    fn a_blade_that_does_not_move_sweeps_nothing() {
        assert!(SweptRegion::new(vertical_blade(1.0), vertical_blade(1.0)).is_none());
        let nan = BladePose {
            heel: DVec3::NAN,
            tip: DVec3::ZERO,
        };
        assert!(SweptRegion::new(nan, vertical_blade(1.0)).is_none());
    }
}
