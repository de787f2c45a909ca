//! The coarse level of the two-level preconditioner: a regular grid of cubes laid over
//! the body, each free node interpolated trilinearly from the eight corners of its cube
//! (the prolongation `P`). A corner is one coarse node per piece of the body it covers
//! (`coarse_pieces.rs`: split where a cut separates its nodes), and only pieces that carry
//! enough of the free nodes' weight, with columns of `P` independent of the others', are
//! kept, so the coarse unknowns follow the body's shape and its cuts, not its bounding box.

use rustc_hash::FxHashMap as HashMap;

use crate::thread_team::{ThreadTeam, for_each_part_of_units, part_count};
use glam::{UVec3, Vec3, Vec3A};

pub use super::coarse_pieces::NodeWeights;
use super::coarse_pieces::{Pieces, pieces};
use super::rest_tet::RestTet;

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
    /// The grid of cubes of edge `cell` over `points`, one coarse node per piece of the
    /// body a corner covers (its free nodes connected through the `tets` marked `live`,
    /// `pieces`); nodes with `free[i] == false` get no weights (their values are fixed,
    /// not solved for).
    pub fn new(
        points: &[Vec3],
        free: &[bool],
        cell: f32,
        (tets, live): (&[RestTet], &[bool]),
    ) -> Self {
        let mut weights = corner_weights(points, free, cell);
        let pieces = pieces(&weights, tets, live);
        let count = prune(&mut weights, &pieces);
        let (transpose_offsets, transpose) = transposed(&weights, count);
        CoarseGrid {
            cell,
            weights,
            count,
            transpose_offsets,
            transpose,
        }
    }

    /// `Pᵀ r`: fine node vectors summed onto the coarse nodes (in f32 SIMD registers, then
    /// written as f64, 3 per node, for the factor), each coarse node's sum in fine-node
    /// order (the same on any thread count).
    pub fn restrict(&self, r: &[Vec3], out: &mut [f64], team: Option<&ThreadTeam>) {
        let node = |c: usize, o: &mut [f64]| {
            let range = self.transpose_offsets[c] as usize..self.transpose_offsets[c + 1] as usize;
            let mut sum = Vec3A::ZERO;
            for &(i, wk) in &self.transpose[range] {
                sum += wk * Vec3A::from(r[i as usize]);
            }
            o.copy_from_slice(&[sum.x as f64, sum.y as f64, sum.z as f64]);
        };
        let parts = part_count(team, self.count, self.count.div_ceil(RESTRICT_TASKS));
        for_each_part_of_units(team, out, 3, parts, |first, mine| {
            for (k, o) in mine.chunks_mut(3).enumerate() {
                node(first + k, o);
            }
        });
    }

    /// Per coarse node, the range of the second list holding its fine nodes and their
    /// weights (the restriction's order; what the GPU's restriction reads).
    pub(crate) fn transposed(&self) -> (&[u32], &[(u32, f32)]) {
        (&self.transpose_offsets, &self.transpose)
    }

    /// `z + (P c)_i`: fine node `i`'s value `z` plus the coarse values `c` interpolated
    /// onto it, corner by corner (what the preconditioner's node pass adds).
    #[inline]
    pub fn add_prolonged(&self, i: usize, c: &[Vec3A], z: Vec3A) -> Vec3A {
        self.weights[i]
            .iter()
            .fold(z, |z, &(id, wk)| z + wk * c[id as usize])
    }
}

/// Parts of the restriction on the team (a few per core on the machines of the issues:
/// each part's setup costs about what a few coarse nodes' sums do).
const RESTRICT_TASKS: usize = 4;

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

/// Per node, its cube's eight corners (numbered in the order the nodes first reach them)
/// and trilinear weights; no weights for a node that is not free.
fn corner_weights(points: &[Vec3], free: &[bool], cell: f32) -> Vec<NodeWeights> {
    let origin = points
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |a, p| a.min(*p))
        - Vec3::splat(0.5 * cell);
    let mut ids: HashMap<UVec3, u32> = HashMap::default();
    let mut weights = vec![[(0u32, 0.0f32); 8]; points.len()];
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
            weights[i][k] = (id, trilinear(t, *c));
        }
    }
    weights
}

/// Make each piece (`piece`: per weight slot, the first slot of its piece) carrying at
/// least [`MIN_SUPPORT`] of weight a coarse node, numbered by corner, then by piece; drop
/// the others, renormalise each node's remaining weights to sum to 1 (constants still
/// interpolate exactly); returns how many are kept.
fn prune(weights: &mut [NodeWeights], pieces: &Pieces) -> usize {
    let piece = &pieces.slot;
    let slot_weight = |s: usize| weights[s / 8][s % 8];
    let mut support = vec![0.0f32; piece.len()];
    for s in 0..piece.len() {
        support[piece[s] as usize] += slot_weight(s).1;
    }
    let mut kept: Vec<usize> = (0..piece.len())
        .filter(|&s| piece[s] as usize == s && support[s] >= MIN_SUPPORT)
        .collect();
    kept.sort_by_key(|&s| (slot_weight(s).0, s));
    let kept = independent(kept, weights, pieces);
    let mut dense = vec![u32::MAX; piece.len()];
    for (n, &s) in kept.iter().enumerate() {
        dense[s] = n as u32;
    }
    for (i, w) in weights.iter_mut().enumerate() {
        let mut total = 0.0;
        for (k, (id, wk)) in w.iter_mut().enumerate() {
            let coarse = dense[piece[8 * i + k] as usize];
            if *wk > 0.0 && coarse != u32::MAX {
                *id = coarse;
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
    kept.len()
}

/// Least share of a coarse node's column of `P` outside the span of the columns before it
/// (relative to its squared length) for the node to be kept.
const MIN_PIVOT: f64 = 1e-3;

/// Most pieces of one fragment whose independence is checked (a dense factorisation of
/// their Gram matrix, `n²` values and `n³/2` operations); a larger fragment keeps every
/// piece, as the whole body did before cuts were split.
const MAX_CHECKED: usize = 1024;

/// The pieces of `kept` (in order) whose columns of `P` are independent of the kept ones
/// before them, fragment by fragment ([`independent_in`]): a small piece cut off from the
/// body can be covered by more corners than it has nodes, and their columns are
/// dependent (the coarse matrix singular). Columns of different fragments share no node.
fn independent(kept: Vec<usize>, weights: &[NodeWeights], pieces: &Pieces) -> Vec<usize> {
    let fragment_of = |s: usize| pieces.fragment[s / 8];
    let mut by_fragment: HashMap<u32, Vec<usize>> = HashMap::default();
    for &s in &kept {
        by_fragment.entry(fragment_of(s)).or_default().push(s);
    }
    let mut nodes_of: HashMap<u32, Vec<usize>> = HashMap::default();
    for (i, f) in pieces.fragment.iter().enumerate() {
        if by_fragment.contains_key(f) {
            nodes_of.entry(*f).or_default().push(i);
        }
    }
    let mut keep = vec![false; pieces.slot.len()];
    for (f, group) in by_fragment {
        let checked = if group.len() <= MAX_CHECKED {
            independent_in(group, &nodes_of[&f], weights, &pieces.slot)
        } else {
            group
        };
        for s in checked {
            keep[s] = true;
        }
    }
    kept.into_iter().filter(|&s| keep[s]).collect()
}

/// The pieces of `group` (in order) whose columns of `P` are independent of the kept ones
/// before them: the pivot of a Cholesky factorisation of their Gram matrix `PᵀP` at least
/// [`MIN_PIVOT`] of its diagonal; `nodes`: the fine nodes of their fragment.
fn independent_in(
    group: Vec<usize>,
    nodes: &[usize],
    weights: &[NodeWeights],
    piece: &[u32],
) -> Vec<usize> {
    let n = group.len();
    let at: HashMap<usize, usize> = group.iter().enumerate().map(|(j, &s)| (s, j)).collect();
    let mut gram = vec![0.0f64; n * n];
    let mut cols = Vec::with_capacity(8);
    for &i in nodes {
        cols.clear();
        for (k, &(_, wk)) in weights[i].iter().enumerate() {
            if let (true, Some(&j)) = (wk > 0.0, at.get(&(piece[8 * i + k] as usize))) {
                cols.push((j, wk as f64));
            }
        }
        for &(a, wa) in &cols {
            for &(b, wb) in &cols {
                gram[a * n + b] += wa * wb;
            }
        }
    }
    // Left-looking Cholesky over the accepted columns, l[j * n + k] = L(j, k), inside the
    // envelope: L(j, k) = 0 left of row j's first nonzero of the Gram matrix.
    let first: Vec<usize> = (0..n)
        .map(|j| (0..j).find(|&c| gram[j * n + c] != 0.0).unwrap_or(j))
        .collect();
    let mut l = vec![0.0f64; n * n];
    let mut accepted: Vec<usize> = Vec::new();
    for j in 0..n {
        let from = accepted.partition_point(|&k| k < first[j]);
        for q in from..accepted.len() {
            let k = accepted[q];
            let start = accepted.partition_point(|&m| m < first[j].max(first[k]));
            let dot: f64 = accepted[start..q]
                .iter()
                .map(|&m| l[j * n + m] * l[k * n + m])
                .sum();
            l[j * n + k] = (gram[j * n + k] - dot) / l[k * n + k];
        }
        let done: f64 = accepted[from..].iter().map(|&m| l[j * n + m].powi(2)).sum();
        let pivot = gram[j * n + j] - done;
        if pivot >= MIN_PIVOT * gram[j * n + j] {
            l[j * n + j] = pivot.sqrt();
            accepted.push(j);
        }
    }
    accepted.into_iter().map(|j| group[j]).collect()
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
    let tets = super::rest_tet::RestTet::all(&mesh);
    let live = vec![true; tets.len()];
    let grid = CoarseGrid::new(&mesh.rest_positions, &free, 0.012, (&tets, &live));
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
        let grid = CoarseGrid::new(&pts, &free, 0.3, (&[], &[]));
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
        grid.restrict(&r, &mut pr, None);
        let c3: Vec<Vec3A> = c
            .chunks(3)
            .map(|v| Vec3A::new(v[0] as f32, v[1] as f32, v[2] as f32))
            .collect();
        let z: Vec<Vec3> = (0..pts.len())
            .map(|i| grid.add_prolonged(i, &c3, Vec3A::ZERO).into())
            .collect();
        // In parallel: the same values.
        let mut pr2 = vec![1.0; 3 * grid.count];
        let team = ThreadTeam::new(2).unwrap();
        grid.restrict(&r, &mut pr2, Some(&team));
        assert_eq!(pr, pr2);
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
        let grid = CoarseGrid::new(&pts, &[true, false], 0.5, (&[], &[]));
        assert!(grid.weights[1].iter().all(|(_, w)| *w == 0.0));
        // The free node sits at the middle of its cube (the grid starts half a cube
        // below the lowest point): each corner carries 1/8, too little to be kept.
        assert_eq!(grid.count, 0);
        assert!(grid.weights[0].iter().all(|(_, w)| *w == 0.0));
    }

    /// Four nodes at the midpoints of a cube face's edges, one tet: each corner of the
    /// face carries a weight of 1, but the four columns of `P` are dependent (corners
    /// A − B + C − D interpolate to zero), as where a piece cut loose covers more corners
    /// than it has nodes. One corner is dropped and the coarse mass matrix factorises.
    #[test]
    fn dependent_corners_are_dropped() {
        let pts = vec![
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            // Fixed: it only moves the grid's origin so the face lies on grid lines.
            Vec3::new(-0.5, -0.5, -0.5),
        ];
        let free = [true, true, true, true, false];
        let tet = RestTet {
            nodes: [0, 1, 2, 3],
            dm_inv: glam::Mat3::IDENTITY,
            volume: 1.0,
        };
        let grid = CoarseGrid::new(&pts, &free, 1.0, (&[tet], &[true]));
        assert_eq!(grid.count, 3, "{:?}", grid.weights);
        let b = [crate::vbd::shape_gradients(&tet.dm_inv)];
        let system = super::super::coarse_system::CoarseSystem::with_assembly(
            &grid,
            (&[tet], &b),
            (&[1.0; 5], 1.0),
        );
        assert!(system.is_ok(), "{:?}", system.err());
    }

    /// A cut through the whole block at x = 22.5 mm (between two layers of nodes, inside
    /// a coarse cube): every coarse node of the split grid interpolates to one side only,
    /// there are more of them than on the whole block, and the coarse matrix factorises.
    #[test]
    fn a_cut_splits_the_corners_it_crosses() {
        let plane = 0.0225;
        let (mesh, _, tets) = test_block();
        let points = &mesh.rest_positions;
        let free: Vec<bool> = points.iter().map(|p| p.x > 1e-4).collect();
        let live: Vec<bool> = tets
            .iter()
            .map(|t| {
                let xs = t.nodes.map(|i| points[i as usize].x);
                !(xs.iter().any(|x| *x < plane) && xs.iter().any(|x| *x > plane))
            })
            .collect();
        let whole = CoarseGrid::new(points, &free, 0.012, (&tets, &vec![true; tets.len()]));
        let split = CoarseGrid::new(points, &free, 0.012, (&tets, &live));
        assert!(
            split.count > whole.count,
            "{} → {}",
            whole.count,
            split.count
        );
        let mut side = vec![None; split.count];
        for (i, w) in split.weights.iter().enumerate() {
            for &(c, _) in w.iter().filter(|(_, wk)| *wk > 0.0) {
                let here = points[i].x > plane;
                let first = *side[c as usize].get_or_insert(here);
                assert_eq!(first, here, "coarse node {c} spans the cut");
            }
        }
        let mass = mesh.lumped_masses(1040.0);
        let b: Vec<_> = tets
            .iter()
            .map(|t| crate::vbd::shape_gradients(&t.dm_inv))
            .collect();
        super::super::coarse_system::CoarseSystem::with_assembly(
            &split,
            (&tets, &b),
            (&mass, 3600.0),
        )
        .expect("factorises");
    }
}
