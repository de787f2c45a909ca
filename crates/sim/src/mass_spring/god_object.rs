//! God-object coupling of a point tool to the tissue surface (Zilles & Salisbury 1995, "A
//! constraint-based god-object method for haptic display", IROS), for the haptic loop of
//! PHYSICS.md §2.6.
//!
//! The device point may sink into the tissue; its *proxy* (the god object) may not. The
//! proxy is born where the device's path first crosses the surface, then rides the
//! surface: it sits on a surface triangle at fixed barycentric weights (so it moves with the
//! tissue) and, each loop, slides to the surface point nearest the device within the
//! triangles around it (a local walk, so it never jumps through the body to the far side).
//! It leaves the surface when the device is back outside. The device feels
//! `F = k (proxy − device)`; the tissue takes `−F`, shared by the triangle's three nodes in
//! the barycentric weights. A coupling to the nearest node instead (the loop's other
//! contact) pulls as well as pushes, and its force jumps as the nearest node changes.

use std::collections::HashMap;

use glam::DVec3;

use super::Rows;
use crate::mesh::{TET_FACES, closest_point_on_triangle};

/// The outward-wound boundary triangles of a tet list and, per node, the triangles on it.
#[derive(Debug, Clone, Default)]
pub struct ProxySurface {
    triangles: Vec<[u32; 3]>,
    node_triangles: Rows,
    tets: usize,
}

impl ProxySurface {
    /// The faces of `tets` used by one tet, wound so their normal points away from the
    /// tet's fourth node at the positions `x`.
    pub fn build(tets: &[[u32; 4]], x: &[DVec3]) -> ProxySurface {
        let mut uses: HashMap<[u32; 3], (u32, [u32; 3], u32)> = HashMap::new();
        for tet in tets {
            for (f, face) in TET_FACES.iter().enumerate() {
                let nodes = face.map(|l| tet[l]);
                let mut key = nodes;
                key.sort_unstable();
                let e = uses.entry(key).or_insert((0, nodes, tet[f]));
                e.0 += 1;
            }
        }
        let mut triangles: Vec<[u32; 3]> = uses
            .into_values()
            .filter(|(n, _, _)| *n == 1)
            .map(|(_, [a, b, c], opposite)| {
                let normal = (x[b as usize] - x[a as usize]).cross(x[c as usize] - x[a as usize]);
                if normal.dot(x[opposite as usize] - x[a as usize]) > 0.0 {
                    [a, c, b]
                } else {
                    [a, b, c]
                }
            })
            .collect();
        triangles.sort_unstable();
        let node_triangles = Rows::build(
            x.len(),
            triangles
                .iter()
                .enumerate()
                .flat_map(|(k, t)| t.map(|v| (v, k as u32))),
        );
        ProxySurface {
            triangles,
            node_triangles,
            tets: tets.len(),
        }
    }

    /// Number of tets the surface was built from (a cut changes it: rebuild).
    pub fn tet_count(&self) -> usize {
        self.tets
    }

    /// The outward-wound triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The corners of triangle `t` at node positions `x`.
    fn corners(&self, t: usize, x: &[DVec3]) -> [DVec3; 3] {
        self.triangles[t].map(|v| x[v as usize])
    }

    /// Triangles sharing a node with triangle `t` (itself included).
    fn around(&self, t: usize) -> impl Iterator<Item = usize> + '_ {
        self.triangles[t].into_iter().flat_map(|v| {
            self.node_triangles
                .row(v as usize)
                .iter()
                .map(|&k| k as usize)
        })
    }
}

/// Where the proxy sits: a surface triangle and barycentric weights on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProxyContact {
    /// Index into [`ProxySurface::triangles`].
    pub triangle: usize,
    /// Barycentric weights of the proxy on the triangle's three nodes.
    pub weights: DVec3,
}

impl ProxyContact {
    /// The proxy's position at node positions `x`.
    pub fn point(&self, surface: &ProxySurface, x: &[DVec3]) -> DVec3 {
        let [a, b, c] = surface.triangles[self.triangle].map(|v| x[v as usize]);
        a * self.weights.x + b * self.weights.y + c * self.weights.z
    }
}

/// A god object: the proxy's contact (none while the device is outside the tissue) and the
/// device's last position.
#[derive(Debug, Clone, Default)]
pub struct GodObject {
    contact: Option<ProxyContact>,
    last_device: Option<DVec3>,
    last_proxy: Option<DVec3>,
}

/// Barycentric weights of point `p` of triangle `abc`.
fn barycentric(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let den = d00 * d11 - d01 * d01;
    if den <= 0.0 {
        return DVec3::new(1.0, 0.0, 0.0);
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    DVec3::new(1.0 - v - w, v, w)
}

/// Where segment `p → q` enters triangle `abc` from its outer side, as the fraction along
/// the segment (Möller–Trumbore), if it does.
fn entry(p: DVec3, q: DVec3, [a, b, c]: [DVec3; 3]) -> Option<f64> {
    let (e1, e2, d) = (b - a, c - a, q - p);
    if d.dot(e1.cross(e2)) >= 0.0 {
        return None; // leaving or parallel: only an entry from outside counts
    }
    let h = d.cross(e2);
    let det = e1.dot(h);
    let s = p - a;
    let u = s.dot(h) / det;
    let qv = s.cross(e1);
    let v = d.dot(qv) / det;
    let t = e2.dot(qv) / det;
    ((0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&t)).then_some(t)
}

/// Of the `triangles` of `surface` (node positions `x`), the one whose closest point to
/// `p` is nearest, and that point; `None` when there are none.
fn nearest_among(
    p: DVec3,
    triangles: impl IntoIterator<Item = usize>,
    surface: &ProxySurface,
    x: &[DVec3],
) -> Option<(usize, DVec3)> {
    triangles
        .into_iter()
        .map(|t| {
            let [a, b, c] = surface.corners(t, x).map(|v| v.as_vec3());
            (
                t,
                closest_point_on_triangle(p.as_vec3(), a, b, c).as_dvec3(),
            )
        })
        .min_by(|a, b| {
            (a.1 - p)
                .length_squared()
                .total_cmp(&(b.1 - p).length_squared())
        })
}

impl GodObject {
    /// The proxy's contact, if the device is in the tissue.
    pub fn contact(&self) -> Option<ProxyContact> {
        self.contact
    }

    /// Move the device to `device` and update the proxy on `surface` at node positions `x`;
    /// returns the proxy's contact. Call [`GodObject::rebind`] after the surface is rebuilt.
    pub fn update(
        &mut self,
        device: DVec3,
        surface: &ProxySurface,
        x: &[DVec3],
    ) -> Option<ProxyContact> {
        let from = self.last_device.replace(device);
        self.contact = match self.contact {
            Some(c) => Self::slide(c, device, surface, x),
            None => from.and_then(|p| Self::enter(p, device, surface, x)),
        };
        self.last_proxy = self.contact.map(|c| c.point(surface, x));
        self.contact
    }

    /// After the surface was rebuilt (a cut changed the tets): a proxy in contact moves to
    /// the new surface's point nearest where it was.
    pub fn rebind(&mut self, surface: &ProxySurface, x: &[DVec3]) {
        self.contact = match (self.contact, self.last_proxy) {
            (Some(_), Some(p)) => Self::nearest(p, surface, x),
            _ => None,
        };
    }

    /// The surface point nearest `p`, over every triangle.
    fn nearest(p: DVec3, surface: &ProxySurface, x: &[DVec3]) -> Option<ProxyContact> {
        let (triangle, q) = nearest_among(p, 0..surface.triangles.len(), surface, x)?;
        let [a, b, c] = surface.corners(triangle, x);
        Some(ProxyContact {
            triangle,
            weights: barycentric(q, a, b, c),
        })
    }

    /// The first surface crossing of the device's path `p → q`.
    fn enter(p: DVec3, q: DVec3, surface: &ProxySurface, x: &[DVec3]) -> Option<ProxyContact> {
        let (lo, hi) = (p.min(q), p.max(q));
        let (triangle, t) = (0..surface.triangles.len())
            .filter(|&k| {
                let c = surface.corners(k, x);
                let (tlo, thi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
                tlo.cmple(hi).all() && thi.cmpge(lo).all()
            })
            .filter_map(|k| entry(p, q, surface.corners(k, x)).map(|f| (k, f)))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let [a, b, c] = surface.corners(triangle, x);
        let weights = barycentric(p + (q - p) * t, a, b, c);
        Some(ProxyContact { triangle, weights })
    }

    /// Walk from `c` to the surface point nearest `device` (at most 16 hops across
    /// neighbouring triangles); `None` once the device is outside the surface there.
    fn slide(
        c: ProxyContact,
        device: DVec3,
        surface: &ProxySurface,
        x: &[DVec3],
    ) -> Option<ProxyContact> {
        let mut here = c.triangle;
        let mut point = nearest_among(device, [here], surface, x)?.1;
        for _ in 0..16 {
            let best = nearest_among(device, surface.around(here), surface, x)?;
            if best.0 == here
                || (best.1 - device).length_squared() >= (point - device).length_squared()
            {
                break;
            }
            (here, point) = best;
        }
        let [a, b, cc] = surface.corners(here, x);
        let normal = (b - a).cross(cc - a);
        if (device - point).dot(normal) > 0.0 {
            return None;
        }
        Some(ProxyContact {
            triangle: here,
            weights: barycentric(point, a, b, cc),
        })
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;
    use crate::mesh::TetMesh;

    fn slab() -> (Vec<[u32; 4]>, Vec<DVec3>) {
        let (mesh, _) = TetMesh::from_raw(block(
            Vec3::ZERO,
            Vec3::new(0.04, 0.04, 0.01),
            UVec3::new(4, 4, 1),
        ))
        .unwrap();
        let x = mesh.rest_positions.iter().map(|p| p.as_dvec3()).collect();
        (mesh.tets, x)
    }

    /// The proxy enters where the path crosses the top face, stays on it while the device
    /// sinks through the whole slab and out of its bottom, slides along it with the device,
    /// and leaves once the device is back above.
    #[test]
    fn proxy_stays_on_the_entered_face_and_leaves_when_the_device_does() {
        let (tets, x) = slab();
        let surface = ProxySurface::build(&tets, &x);
        assert_eq!(surface.triangles().len(), 2 * (16 + 16 + 4 * 4));
        let mut god = GodObject::default();
        assert!(
            god.update(DVec3::new(0.013, 0.017, 0.012), &surface, &x)
                .is_none()
        );
        let c = god
            .update(DVec3::new(0.013, 0.017, 0.008), &surface, &x)
            .expect("entered");
        let p = c.point(&surface, &x);
        assert!((p - DVec3::new(0.013, 0.017, 0.01)).length() < 1e-9, "{p}");
        for z in [0.005, 0.0, -0.01] {
            let c = god
                .update(DVec3::new(0.013, 0.017, z), &surface, &x)
                .expect("inside");
            let p = c.point(&surface, &x);
            assert!(
                (p.z - 0.01).abs() < 1e-9,
                "proxy left the top face at device z {z}: {p}"
            );
        }
        let c = god
            .update(DVec3::new(0.031, 0.022, 0.004), &surface, &x)
            .expect("slid");
        let p = c.point(&surface, &x);
        assert!((p - DVec3::new(0.031, 0.022, 0.01)).length() < 1e-6, "{p}");
        assert!(
            god.update(DVec3::new(0.031, 0.022, 0.0101), &surface, &x)
                .is_none()
        );
    }

    /// A path entering through a side face gets the side face; one that never reaches the
    /// tissue gets nothing.
    #[test]
    fn entry_is_the_first_crossing_from_outside() {
        let (tets, x) = slab();
        let surface = ProxySurface::build(&tets, &x);
        let mut god = GodObject::default();
        god.update(DVec3::new(-0.01, 0.02, 0.005), &surface, &x);
        let c = god
            .update(DVec3::new(0.01, 0.02, 0.005), &surface, &x)
            .expect("entered");
        assert!(c.point(&surface, &x).x.abs() < 1e-9);
        let mut miss = GodObject::default();
        miss.update(DVec3::new(-0.01, 0.02, 0.02), &surface, &x);
        assert!(
            miss.update(DVec3::new(0.05, 0.02, 0.02), &surface, &x)
                .is_none()
        );
    }
}
