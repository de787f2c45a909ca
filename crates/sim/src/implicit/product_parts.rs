//! The Hessian product's per-node partial sums: one node vector per fixed range of the
//! active chunks of tets ([`PRODUCT_PARTS`] of them, summed apart and added in order, so
//! the product does not depend on the thread count), each with the range of nodes its
//! tets reach. A product zeroes and sums only inside each part's range and the node pass
//! reads a part only there: on a mesh whose tets are in node order (every generated one)
//! a part reaches about a quarter of the nodes, where zeroing and reading every part's
//! whole vector cost a sixth of the product.

use std::ops::Range;

use glam::Vec3A;

use super::rest_tet::RestTet;
use crate::xpbd::lanes::LANES;

/// Fixed ranges of the active tets whose product forces are summed apart.
pub(super) const PRODUCT_PARTS: usize = 4;

/// The parts' node vectors and the nodes each reaches. Outside its range a part's vector
/// is zero.
#[derive(Debug, Clone, Default)]
pub(super) struct ProductParts {
    sums: Vec<Vec<Vec3A>>,
    nodes: Vec<Range<usize>>,
}

impl ProductParts {
    /// Part `k` of the `active` chunks (ranges in order, about equal).
    pub(super) fn chunks(active: &[u32], k: usize) -> &[u32] {
        let per = active.len().div_ceil(PRODUCT_PARTS).max(1);
        &active[(k * per).min(active.len())..((k + 1) * per).min(active.len())]
    }

    /// Take the parts of the `active` chunks of `tets` on a mesh of `nodes` nodes (once a
    /// step): each part's range becomes the nodes its chunks' tets reach, every value
    /// outside it zero.
    pub(super) fn set_chunks(&mut self, tets: &[RestTet], active: &[u32], nodes: usize) {
        self.sums.resize_with(PRODUCT_PARTS, Vec::new);
        self.nodes.resize(PRODUCT_PARTS, 0..0);
        for (k, (sums, range)) in self.sums.iter_mut().zip(&mut self.nodes).enumerate() {
            if sums.len() == nodes {
                sums[range.clone()].fill(Vec3A::ZERO);
            } else {
                *sums = vec![Vec3A::ZERO; nodes];
            }
            *range = reach(tets, Self::chunks(active, k));
        }
    }

    /// The parts' node vectors, and the nodes each reaches (a product zeroes a part over
    /// its range, then sums into it there).
    pub(super) fn split(&mut self) -> (&mut [Vec<Vec3A>], &[Range<usize>]) {
        (&mut self.sums, &self.nodes)
    }

    /// `start + Σ` of the parts at node `i`, in part order, skipping the parts that do not
    /// reach it (their value there is zero).
    #[inline]
    pub(super) fn add_at(&self, i: usize, start: Vec3A) -> Vec3A {
        self.sums
            .iter()
            .zip(&self.nodes)
            .filter(|(_, r)| r.contains(&i))
            .fold(start, |sum, (s, _)| sum + s[i])
    }
}

/// The nodes the tets of `chunks` (of eight, mesh order) reach, lowest to highest.
fn reach(tets: &[RestTet], chunks: &[u32]) -> Range<usize> {
    let nodes = chunks.iter().flat_map(|&c| {
        let c = c as usize;
        tets[c * LANES..((c + 1) * LANES).min(tets.len())]
            .iter()
            .flat_map(|t| t.nodes)
    });
    let (lo, hi) = nodes.fold((u32::MAX, 0), |(lo, hi), n| (lo.min(n), hi.max(n)));
    if lo > hi {
        0..0
    } else {
        lo as usize..hi as usize + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After the chunks change, each part is zero outside its new range (nothing left of
    /// the last step's sums), its range holds every node its tets reach, and the node
    /// pass's sum skipping the parts that do not reach a node is the sum of every part.
    #[test]
    fn a_part_is_zero_outside_the_nodes_its_tets_reach() {
        let (mesh, _, tets) = crate::implicit::coarse_grid::test_block();
        let n = mesh.node_count();
        let chunks = tets.len().div_ceil(LANES) as u32;
        let mut parts = ProductParts::default();
        let all: Vec<u32> = (0..chunks).collect();
        // A later step's active chunks: every third, so the ranges move.
        let some: Vec<u32> = (0..chunks).filter(|c| c % 3 == 1).collect();
        for active in [&all, &some] {
            parts.set_chunks(&tets, active, n);
            let (sums, ranges) = parts.split();
            for (k, (s, r)) in sums.iter_mut().zip(ranges).enumerate() {
                for &c in ProductParts::chunks(active, k) {
                    let c = c as usize;
                    for t in &tets[c * LANES..((c + 1) * LANES).min(tets.len())] {
                        assert!(t.nodes.iter().all(|&i| r.contains(&(i as usize))));
                    }
                }
                for (i, v) in s.iter().enumerate() {
                    assert!(
                        r.contains(&i) || *v == Vec3A::ZERO,
                        "part {k} node {i}: {v}"
                    );
                }
                // What a product leaves: a value at every node of the range.
                s[r.clone()].fill(Vec3A::splat(k as f32 + 1.0));
            }
            for i in 0..n {
                let every: Vec3A = parts.sums.iter().map(|s| s[i]).sum();
                assert_eq!(parts.add_at(i, Vec3A::ZERO), every);
            }
        }
    }
}
