//! The partitioned sweep (issue 35, item 1): the mesh cut into [`SWEEP_BLOCKS`] slabs of
//! nodes along its longest axis, so that one sweep synchronises the threads a handful of
//! times instead of once per colour. A tet whose nodes lie in one slab is that block's; the
//! blocks share no node, so each is projected by one task, colour after colour, with no
//! barrier between colours. A tet across two neighbouring slabs belongs to the cut between
//! them: the even cuts touch disjoint slab pairs and run in parallel, then the odd ones. A
//! tet across more than two slabs (a slab thinner than a tet) is projected last, alone.
//!
//! The slots stay in colour order (the GPU and the coloured sweep read them so); within a
//! colour they are sorted by group, so each group's tets of a colour are one contiguous run
//! for the SIMD lanes. The block count does not depend on the thread count, so the result
//! does not either.

use std::ops::Range;

use glam::Vec3;

/// Slabs of the partitioned sweep: fixed, so results do not depend on the machine; eight
/// keep two to four threads busy with the blocks in any order.
pub const SWEEP_BLOCKS: usize = 8;

/// Group of each tet: `0..B` a block, `B + k` the cut between slabs `k` and `k + 1`,
/// `2B − 1` the tets across more than two slabs.
pub(crate) fn tet_groups(rest: &[Vec3], tets: &[[u32; 4]]) -> Vec<u32> {
    let (lo, hi) = rest.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let span = hi - lo;
    let axis = if span.x >= span.y && span.x >= span.z {
        0
    } else if span.y >= span.z {
        1
    } else {
        2
    };
    let b = SWEEP_BLOCKS as f32;
    let slab = |i: u32| {
        let t = (rest[i as usize][axis] - lo[axis]) / span[axis].max(f32::MIN_POSITIVE);
        ((t * b) as usize).min(SWEEP_BLOCKS - 1)
    };
    tets.iter()
        .map(|tet| {
            let s = tet.map(slab);
            let (a, z) = (*s.iter().min().unwrap(), *s.iter().max().unwrap());
            (match z - a {
                0 => a,
                1 => SWEEP_BLOCKS + a,
                _ => 2 * SWEEP_BLOCKS - 1,
            }) as u32
        })
        .collect()
}

/// Which slots one sweep projects in which phase.
#[derive(Debug, Clone)]
pub(crate) struct SweepPlan {
    /// `runs[g][c]`: the slots of group `g` and colour `c` (contiguous).
    pub runs: Vec<Vec<Range<usize>>>,
    /// Groups projected in parallel, phase after phase: the blocks, the even cuts, the odd
    /// cuts, the wide tets.
    pub phases: Vec<Vec<usize>>,
}

impl SweepPlan {
    /// The plan of slots ordered by (colour, group): `keys[s]` is slot `s`'s pair.
    pub fn new(keys: &[(u32, u32)], colours: usize) -> Self {
        let groups = 2 * SWEEP_BLOCKS;
        let mut runs = vec![vec![0..0; colours]; groups];
        let mut s = 0;
        while s < keys.len() {
            let (c, g) = keys[s];
            let end = s + keys[s..].iter().take_while(|&&k| k == (c, g)).count();
            runs[g as usize][c as usize] = s..end;
            s = end;
        }
        let b = SWEEP_BLOCKS;
        let cuts = |parity| (b + parity..2 * b - 1).step_by(2).collect();
        SweepPlan {
            runs,
            phases: vec![(0..b).collect(), cuts(0), cuts(1), vec![2 * b - 1]],
        }
    }

    /// The slots of each colour (all its groups' runs, which are consecutive).
    pub fn colour_ranges(&self) -> Vec<Range<usize>> {
        (0..self.runs[0].len())
            .map(|c| {
                let runs = self.runs.iter().map(|g| &g[c]).filter(|r| !r.is_empty());
                let start = runs.clone().map(|r| r.start).min().unwrap_or(0);
                start..runs.map(|r| r.end).max().unwrap_or(start)
            })
            .collect()
    }

    /// Slots projected in each phase (for tests and the bench).
    pub fn phase_sizes(&self) -> Vec<usize> {
        self.phases
            .iter()
            .map(|p| p.iter().flat_map(|&g| &self.runs[g]).map(|r| r.len()).sum())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tet in one slab is the slab's, one across two neighbours the cut's, one across
    /// three the wide group's; the longest axis is the one cut.
    #[test]
    fn tets_go_to_their_slab_or_cut() {
        let rest: Vec<Vec3> = (0..=16)
            .map(|i| Vec3::new(0.0, i as f32 / 16.0, 0.0))
            .collect();
        let g = tet_groups(
            &rest,
            &[[0, 1, 0, 1], [1, 2, 1, 2], [2, 3, 2, 3], [0, 5, 0, 5]],
        );
        assert_eq!(g, [0, 8, 1, 15]);
    }

    /// Runs are the contiguous (colour, group) stretches; phases keep disjoint slab pairs.
    #[test]
    fn runs_follow_the_sorted_keys() {
        let keys = [(0, 0), (0, 0), (0, 3), (0, 9), (1, 0), (1, 8)];
        let p = SweepPlan::new(&keys, 2);
        assert_eq!(p.runs[0], [0..2, 4..5]);
        assert_eq!(p.runs[3][0], 2..3);
        assert_eq!(p.runs[9][0], 3..4);
        assert_eq!(p.runs[8][1], 5..6);
        assert_eq!(p.phases[1], [8, 10, 12, 14]);
        assert_eq!(p.phases[2], [9, 11, 13]);
        assert_eq!(p.phase_sizes(), [4, 1, 1, 0]);
        assert_eq!(p.colour_ranges(), [0..4, 4..6]);
    }
}
