//! Memory in the order it is used (issue 35, item 2): the tets of each colour (and of each
//! group of the partitioned sweep) stored along a Morton curve through their rest
//! centroids, so that the eight tets of a SIMD block, and the blocks one task projects
//! after another, touch neighbouring nodes.
//!
//! Tets of one colour share no node, so the order inside a colour changes no result, to the
//! bit: the colouring itself (greedy, in mesh order) and every sum stay as they are. The
//! mesh, the node numbering and every output keep the user's numbering; only the solver's
//! slots (`Solver::slot_tets`) move.

use glam::Vec3;

/// Bits of the Morton key per axis (three axes in a `u64`).
const BITS: u32 = 21;

/// How the solver orders the tets inside each colour and group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TetOrder {
    /// Along a Morton curve through the rest centroids (the default).
    #[default]
    Locality,
    /// In mesh index order, as before the locality sort: for tests and measurement.
    Mesh,
}

impl TetOrder {
    /// The sort key of each tet inside its colour and group (all zero in mesh order, so
    /// the tet index decides).
    pub(crate) fn keys(self, rest: &[Vec3], tets: &[[u32; 4]]) -> Vec<u64> {
        match self {
            TetOrder::Locality => morton_keys(rest, tets),
            TetOrder::Mesh => vec![0; tets.len()],
        }
    }
}

/// Morton key of each tet's rest centroid, quantised to [`BITS`] bits an axis over the
/// cube that holds the nodes' bounding box.
pub(crate) fn morton_keys(rest: &[Vec3], tets: &[[u32; 4]]) -> Vec<u64> {
    let (lo, hi) = rest.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let side = (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let cells = ((1u32 << BITS) - 1) as f32;
    tets.iter()
        .map(|t| {
            let c = t.iter().map(|&i| rest[i as usize]).sum::<Vec3>() * 0.25;
            let q = ((c - lo) / side * cells).clamp(Vec3::ZERO, Vec3::splat(cells));
            spread(q.x as u32) | spread(q.y as u32) << 1 | spread(q.z as u32) << 2
        })
        .collect()
}

/// The low [`BITS`] bits of `v`, two zero bits put between each.
fn spread(v: u32) -> u64 {
    let mut x = (v & ((1 << BITS) - 1)) as u64;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bit `b` of each coordinate lands at bit `3b + axis`.
    #[test]
    fn spread_interleaves_the_bits() {
        assert_eq!(spread(0b1), 0b1);
        assert_eq!(spread(0b11), 0b1001);
        assert_eq!(spread(0b101), 1 | 1 << 6);
        assert_eq!(spread((1 << BITS) - 1), 0x1249_2492_4924_9249);
    }

    /// Neighbouring tets get keys that sort them cell by cell: the four octant corners of
    /// a unit cube in Morton order (x, then y, then z fastest-to-slowest).
    #[test]
    fn keys_follow_the_z_curve() {
        let rest: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2) as f32))
            .collect();
        // Degenerate "tets" at a corner each: their centroid is that corner.
        let tets: Vec<[u32; 4]> = [6, 1, 3, 0].iter().map(|&i| [i; 4]).collect();
        let keys = morton_keys(&rest, &tets);
        let mut order: Vec<usize> = (0..tets.len()).collect();
        order.sort_by_key(|&t| keys[t]);
        assert_eq!(order, [3, 1, 2, 0]);
        assert_eq!(TetOrder::Mesh.keys(&rest, &tets), [0; 4]);
    }
}
