//! Triangulation of a simple polygon by ear clipping (blade outlines: tens of points).

use glam::Vec2;

/// Triangles `[a, b, c]` (indices into `poly`) covering the simple polygon `poly`, each
/// wound counter-clockwise (positive area in the polygon's own x, y). `n − 2` triangles.
pub(crate) fn triangulate(poly: &[Vec2]) -> Vec<[u32; 3]> {
    let n = poly.len();
    let mut idx: Vec<usize> = (0..n).collect();
    if signed_area(poly) < 0.0 {
        idx.reverse();
    }
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    let mut tris = Vec::with_capacity(n.saturating_sub(2));
    while idx.len() > 3 {
        let m = idx.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            let (pa, pb, pc) = (poly[a], poly[b], poly[c]);
            if cross(pa, pb, pc) <= 0.0 {
                return false; // reflex or degenerate corner
            }
            idx.iter().all(|&j| {
                j == a
                    || j == b
                    || j == c
                    || !(cross(pa, pb, poly[j]) >= 0.0
                        && cross(pb, pc, poly[j]) >= 0.0
                        && cross(pc, pa, poly[j]) >= 0.0)
            })
        });
        // A simple polygon always has an ear; float noise on near-collinear points may
        // hide it, then clip the flattest corner.
        let i = ear.unwrap_or_else(|| {
            (0..m)
                .max_by(|&x, &y| {
                    let c = |i: usize| {
                        cross(
                            poly[idx[(i + m - 1) % m]],
                            poly[idx[i]],
                            poly[idx[(i + 1) % m]],
                        )
                    };
                    c(x).total_cmp(&c(y))
                })
                .unwrap_or(0)
        });
        tris.push([
            idx[(i + m - 1) % m] as u32,
            idx[i] as u32,
            idx[(i + 1) % m] as u32,
        ]);
        idx.remove(i);
    }
    if idx.len() == 3 {
        tris.push([idx[0] as u32, idx[1] as u32, idx[2] as u32]);
    }
    tris
}

/// Signed area (positive counter-clockwise).
pub(crate) fn signed_area(poly: &[Vec2]) -> f32 {
    let n = poly.len();
    0.5 * (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f32>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concave_polygon_area_is_preserved() {
        // An L shape, clockwise.
        let l = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, 2.0),
            Vec2::new(1.0, 2.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(2.0, 1.0),
            Vec2::new(2.0, 0.0),
        ];
        let tris = triangulate(&l);
        assert_eq!(tris.len(), 4);
        let area: f32 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| l[i as usize]);
                0.5 * (b - a).perp_dot(c - a)
            })
            .inspect(|&a| assert!(a > 0.0))
            .sum();
        assert!((area - 3.0).abs() < 1e-6);
    }
}
