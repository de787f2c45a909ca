//! The coarse level of the two-level preconditioner: a regular grid of cubes laid over
//! the body, each free node interpolated trilinearly from the eight corners of its cube
//! (the prolongation `P`). Only corners that carry enough of the free nodes' weight are
//! kept, so the coarse unknowns follow the body's shape, not its bounding box.

use std::collections::HashMap;

use glam::{UVec3, Vec3};
use rayon::prelude::*;

/// The eight corner offsets of a cube, in trilinear order.
const CORNERS: [UVec3; 8] = [
    UVec3::new(0, 0, 0),
    UVec3::new(1, 0, 0),
    UVec3::new(0, 1, 0),
    UVec3::new(1, 1, 0),
    UVec3::new(0, 0, 1),
    UVec3::new(1, 0, 1),
    UVec3::new(0, 1, 1),
    UVec3::new(1, 1, 1),
];

/// A fine node's coarse corners and their weights (all zero for a node that is not free).
pub type NodeWeights = [(u32, f32); 8];

/// The prolongation from coarse corners to fine nodes.
#[derive(Debug, Clone)]
pub struct CoarseGrid {
    /// Edge of a cube, m.
    pub cell: f32,
    /// Per fine node: its coarse corners and weights (they sum to 1 for a free node).
    pub weights: Vec<NodeWeights>,
    /// Coarse nodes kept.
    pub count: usize,
    /// Per coarse node, the range of [`CoarseGrid::transpose`] holding its fine nodes.
    transpose_offsets: Vec<u32>,
    /// The fine nodes each coarse node interpolates to, with their weights (`weights`
    /// transposed, so the restriction is a gather, in parallel and in a fixed order).
    transpose: Vec<(u32, f32)>,
}

impl CoarseGrid {
    /// The grid of cubes of edge `cell` over `points`; nodes with `free[i] == false` get no
    /// weights (their values are fixed, not solved for).
    pub fn new(points: &[Vec3], free: &[bool], cell: f32) -> Self {
        let origin = points
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |a, p| a.min(*p))
            - Vec3::splat(0.5 * cell);
        let mut ids: HashMap<UVec3, u32> = HashMap::new();
        let mut weights = vec![[(0u32, 0.0f32); 8]; points.len()];
        let mut support: Vec<f32> = Vec::new();
        for (i, p) in points.iter().enumerate() {
            if !free[i] {
                continue;
            }
            let g = (*p - origin) / cell;
            let base = g.floor();
            let t = g - base;
            let base = base.as_uvec3();
            for (k, c) in CORNERS.iter().enumerate() {
                let next = ids.len() as u32;
                let id = *ids.entry(base + *c).or_insert(next);
                support.resize(ids.len(), 0.0);
                let w = trilinear(t, *c);
                support[id as usize] += w;
                weights[i][k] = (id, w);
            }
        }
        let count = prune(&mut weights, &support);
        let (transpose_offsets, transpose) = transposed(&weights, count);
        CoarseGrid {
            cell,
            weights,
            count,
            transpose_offsets,
            transpose,
        }
    }

    /// `Pᵀ r`: fine node vectors summed onto the coarse nodes (f64, 3 per node), each
    /// coarse node's sum in fine-node order (the same on any thread count).
    pub fn restrict(&self, r: &[Vec3], out: &mut [f64], parallel: bool) {
        let node = |(c, o): (usize, &mut [f64])| {
            let range = self.transpose_offsets[c] as usize..self.transpose_offsets[c + 1] as usize;
            let mut sum = [0.0f64; 3];
            for &(i, wk) in &self.transpose[range] {
                let r = r[i as usize];
                sum[0] += (wk * r.x) as f64;
                sum[1] += (wk * r.y) as f64;
                sum[2] += (wk * r.z) as f64;
            }
            o.copy_from_slice(&sum);
        };
        if parallel {
            out.par_chunks_mut(3)
                .enumerate()
                .with_min_len(8)
                .for_each(node);
        } else {
            out.chunks_mut(3).enumerate().for_each(node);
        }
    }

    /// Per coarse node, the range of the second list holding its fine nodes and their
    /// weights (the restriction's order; what the GPU's restriction reads).
    pub(crate) fn transposed(&self) -> (&[u32], &[(u32, f32)]) {
        (&self.transpose_offsets, &self.transpose)
    }

    /// `z += P c`: coarse values interpolated onto the fine nodes.
    pub fn prolong_add(&self, c: &[f64], z: &mut [Vec3], parallel: bool) {
        let node = |(w, z): (&NodeWeights, &mut Vec3)| {
            for &(id, wk) in w {
                let o = 3 * id as usize;
                *z += wk * Vec3::new(c[o] as f32, c[o + 1] as f32, c[o + 2] as f32);
            }
        };
        if parallel {
            self.weights
                .par_iter()
                .zip(z.par_iter_mut())
                .with_min_len(PROLONG_CHUNK)
                .for_each(node);
        } else {
            self.weights.iter().zip(z.iter_mut()).for_each(node);
        }
    }
}

/// Fine nodes per rayon task of the prolongation.
const PROLONG_CHUNK: usize = 1024;

/// `weights` (fine node → its corners) transposed: per coarse node of `count`, the range
/// of the list of (fine node, weight) pairs with a nonzero weight, in fine-node order.
fn transposed(weights: &[NodeWeights], count: usize) -> (Vec<u32>, Vec<(u32, f32)>) {
    let mut offsets = vec![0u32; count + 1];
    for w in weights {
        for &(id, _) in w.iter().filter(|(_, wk)| *wk > 0.0) {
            offsets[id as usize + 1] += 1;
        }
    }
    for c in 0..count {
        offsets[c + 1] += offsets[c];
    }
    let mut fill = offsets.clone();
    let mut list = vec![(0u32, 0.0f32); offsets[count] as usize];
    for (i, w) in weights.iter().enumerate() {
        for &(id, wk) in w.iter().filter(|(_, wk)| *wk > 0.0) {
            let at = &mut fill[id as usize];
            list[*at as usize] = (i as u32, wk);
            *at += 1;
        }
    }
    (offsets, list)
}

/// Least total weight a corner must carry to be a coarse node, in fine nodes: a corner
/// that only grazes the body (a node or two near the far side of its cubes) would make a
/// column nearly dependent on its neighbours' and the coarse matrix numerically singular.
const MIN_SUPPORT: f32 = 0.5;

/// Drop corners supporting less than [`MIN_SUPPORT`], renormalise each node's remaining
/// weights to sum to 1 (constants still interpolate exactly) and number the kept corners
/// densely; returns how many are kept.
fn prune(weights: &mut [NodeWeights], support: &[f32]) -> usize {
    let mut dense = vec![u32::MAX; support.len()];
    let mut count = 0u32;
    for (id, s) in support.iter().enumerate() {
        if *s >= MIN_SUPPORT {
            dense[id] = count;
            count += 1;
        }
    }
    for w in weights.iter_mut() {
        let mut total = 0.0;
        for (id, wk) in w.iter_mut() {
            if *wk > 0.0 && dense[*id as usize] != u32::MAX {
                *id = dense[*id as usize];
                total += *wk;
            } else {
                *id = 0;
                *wk = 0.0;
            }
        }
        for (_, wk) in w.iter_mut() {
            *wk = if total > 0.0 { *wk / total } else { 0.0 };
        }
    }
    count as usize
}

/// The trilinear weight of corner `c` at local coordinates `t` in the cube.
fn trilinear(t: Vec3, c: UVec3) -> f32 {
    let axis = |t: f32, c: u32| if c == 1 { t } else { 1.0 - t };
    axis(t.x, c.x) * axis(t.y, c.y) * axis(t.z, c.z)
}

/// A 4 × 2 × 1 cm block of tets with its x = 0 face fixed, on a 12 mm coarse grid: the
/// mesh, the grid and the tets (the coarse level's tests).
#[cfg(test)]
pub(crate) fn test_block() -> (
    crate::mesh::TetMesh,
    CoarseGrid,
    Vec<super::rest_tet::RestTet>,
) {
    let raw = crate::generate::block(
        Vec3::ZERO,
        Vec3::new(0.04, 0.02, 0.01),
        glam::UVec3::new(8, 4, 2),
    );
    let mesh = crate::mesh::TetMesh::from_raw(raw).unwrap().0;
    let free: Vec<bool> = (0..mesh.node_count())
        .map(|i| mesh.rest_positions[i].x > 1e-4)
        .collect();
    let grid = CoarseGrid::new(&mesh.rest_positions, &free, 0.012);
    let tets = super::rest_tet::RestTet::all(&mesh);
    (mesh, grid, tets)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_restriction_is_the_transpose() {
        let pts: Vec<Vec3> = (0..50)
            .map(|i| {
                let f = i as f32;
                Vec3::new((f * 0.37).sin(), (f * 0.71).cos(), f * 0.013)
            })
            .collect();
        let free = vec![true; pts.len()];
        let grid = CoarseGrid::new(&pts, &free, 0.3);
        for w in &grid.weights {
            let s: f32 = w.iter().map(|(_, w)| w).sum();
            assert!(s == 0.0 || (s - 1.0).abs() < 1e-5, "{s}");
        }
        assert!(grid.weights.iter().any(|w| w.iter().any(|(_, w)| *w > 0.0)));
        let r: Vec<Vec3> = pts.iter().map(|p| *p * 2.0 + Vec3::X).collect();
        let c: Vec<f64> = (0..3 * grid.count)
            .map(|k| (k as f64 * 0.1).cos())
            .collect();
        let mut pr = vec![0.0; 3 * grid.count];
        grid.restrict(&r, &mut pr, false);
        let mut z = vec![Vec3::ZERO; pts.len()];
        grid.prolong_add(&c, &mut z, false);
        // In parallel: the same values.
        let mut pr2 = vec![1.0; 3 * grid.count];
        grid.restrict(&r, &mut pr2, true);
        assert_eq!(pr, pr2);
        let mut z2 = vec![Vec3::ZERO; pts.len()];
        grid.prolong_add(&c, &mut z2, true);
        assert_eq!(z, z2);
        // (Pᵀ r)·c == r·(P c)
        let lhs: f64 = pr.iter().zip(&c).map(|(a, b)| a * b).sum();
        let rhs: f64 = r.iter().zip(&z).map(|(a, b)| a.dot(*b) as f64).sum();
        assert!(
            (lhs - rhs).abs() < 1e-4 * lhs.abs().max(1.0),
            "{lhs} vs {rhs}"
        );
    }

    #[test]
    fn fixed_nodes_get_no_weight() {
        let pts = vec![Vec3::ZERO, Vec3::ONE];
        let grid = CoarseGrid::new(&pts, &[true, false], 0.5);
        assert!(grid.weights[1].iter().all(|(_, w)| *w == 0.0));
        // The free node sits at the middle of its cube (the grid starts half a cube
        // below the lowest point): each corner carries 1/8, too little to be kept.
        assert_eq!(grid.count, 0);
        assert!(grid.weights[0].iter().all(|(_, w)| *w == 0.0));
    }
}
