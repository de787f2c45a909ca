//! The slots packed for the SIMD lanes (issue 35, item 2): eight consecutive slots of a
//! colour in one [`LaneBlock`], each value of the eight stored side by side, so that a
//! lane value (`Dm⁻¹` entry, compliance, live mask, node index) is one contiguous load
//! instead of eight scattered ones. Only the node positions and inverse masses are still
//! gathered, by the node indices.
//!
//! A block never straddles two spans (a colour, or one group's run of a colour in the
//! partitioned sweep), so each span is whole blocks and one task's; its last block is
//! padded with lanes that are not live. Packed next to the slots (which the scalar kernel
//! and the GPU read), kept in step with their live flags by [`LaneSlots::set_live`].

use std::ops::Range;

use super::lanes::LANES;
use super::tet_slot::TetSlot;

/// Eight slots of one span, value by value.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
pub(crate) struct LaneBlock {
    /// `dm_inv[3c + r][k]`: row r of column c of lane k's `Dm⁻¹` (identity when padding).
    pub dm_inv: [[f32; LANES]; 9],
    /// `α̃_H` per lane (1 when padding).
    pub alpha_h: [f32; LANES],
    /// `α̃_D` per lane (1 when padding).
    pub alpha_d: [f32; LANES],
    /// All bits set in a live lane, clear otherwise (padding too).
    pub live: [f32; LANES],
    /// `nodes[j][k]`: node j of lane k's tet (of lane 0's when padding: nodes no other
    /// block of the colour touches, so every lane can be read, [`super::lane_nodes`]).
    pub nodes: [[u32; LANES]; 4],
    /// Slot of lane 0; lane k is slot `first + k`.
    pub first: u32,
    /// Lanes holding a slot (the rest pad the span's last block).
    pub count: u32,
}

impl LaneBlock {
    /// The block of `slots` (at most [`LANES`]), the first of them slot `first`.
    fn pack(slots: &[TetSlot], first: usize) -> LaneBlock {
        let mut b = LaneBlock {
            dm_inv: std::array::from_fn(|e| [if e % 4 == 0 { 1.0 } else { 0.0 }; LANES]),
            alpha_h: [1.0; LANES],
            alpha_d: [1.0; LANES],
            live: [0.0; LANES],
            nodes: [[0; LANES]; 4],
            first: first as u32,
            count: slots.len() as u32,
        };
        for (k, s) in slots.iter().enumerate() {
            let m = s.terms.dm_inv.to_cols_array();
            for (e, v) in m.iter().enumerate() {
                b.dm_inv[e][k] = *v;
            }
            (b.alpha_h[k], b.alpha_d[k]) = (s.terms.alpha_h, s.terms.alpha_d);
            for j in 0..4 {
                b.nodes[j][k] = s.nodes[j];
            }
            b.set_live(k, s.live);
        }
        for j in 0..4 {
            let first = b.nodes[j][0];
            b.nodes[j][slots.len()..].fill(first);
        }
        b
    }

    /// Mark lane `k` live or not.
    fn set_live(&mut self, k: usize, live: bool) {
        self.live[k] = f32::from_bits(if live { u32::MAX } else { 0 });
    }

    /// Whether lane `k` holds a live tet.
    #[inline(always)]
    pub fn is_live(&self, k: usize) -> bool {
        self.live[k].to_bits() != 0
    }
}

/// The slots of some spans, packed block by block.
#[derive(Debug, Clone)]
pub(crate) struct LaneSlots {
    /// The blocks, span after span.
    pub blocks: Vec<LaneBlock>,
    /// The blocks of each span, in the order the spans were given.
    pub spans: Vec<Range<usize>>,
    /// `LANES × block + lane` of each slot packed.
    lane_of_slot: Vec<u32>,
}

impl LaneSlots {
    /// `slots` packed span by span (disjoint ranges of slots; slots in none stay out).
    pub fn new(slots: &[TetSlot], spans: impl IntoIterator<Item = Range<usize>>) -> Self {
        let mut blocks = Vec::new();
        let mut lane_of_slot = vec![u32::MAX; slots.len()];
        let spans = spans
            .into_iter()
            .map(|span| {
                let start = blocks.len();
                for first in span.clone().step_by(LANES) {
                    let end = (first + LANES).min(span.end);
                    for (k, l) in lane_of_slot[first..end].iter_mut().enumerate() {
                        *l = (LANES * blocks.len() + k) as u32;
                    }
                    blocks.push(LaneBlock::pack(&slots[first..end], first));
                }
                start..blocks.len()
            })
            .collect();
        LaneSlots {
            blocks,
            spans,
            lane_of_slot,
        }
    }

    /// Mark slot `s` live or not (as its [`TetSlot::live`]).
    pub fn set_live(&mut self, s: usize, live: bool) {
        let l = self.lane_of_slot[s] as usize;
        if l != u32::MAX as usize {
            self.blocks[l / LANES].set_live(l % LANES, live);
        }
    }

    /// The slots from the first of `blocks` to the end of the last (contiguous: a span's
    /// blocks hold consecutive slots).
    pub fn slot_range(blocks: &[LaneBlock]) -> Range<usize> {
        match (blocks.first(), blocks.last()) {
            (Some(a), Some(z)) => a.first as usize..(z.first + z.count) as usize,
            _ => 0..0,
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, Vec3};

    use super::*;
    use crate::xpbd::neo_hookean::TetTerms;

    /// Slot `s`, its values telling it apart.
    fn slot(s: usize) -> TetSlot {
        let f = s as f32;
        TetSlot {
            nodes: [
                4 * s as u32,
                4 * s as u32 + 1,
                4 * s as u32 + 2,
                4 * s as u32 + 3,
            ],
            terms: TetTerms {
                dm_inv: Mat3::from_cols(
                    Vec3::new(f, 1.0, 2.0),
                    Vec3::new(3.0, f, 5.0),
                    Vec3::new(6.0, 7.0, f),
                ),
                alpha_h: 0.5 * f,
                alpha_d: 0.25 * f,
                gamma: 1.0,
            },
            live: s != 3,
        }
    }

    /// Each span is whole blocks, lane k of a block is slot `first + k` value by value,
    /// padding lanes are identity, not live and name lane 0's nodes, and `set_live` reaches the right lane.
    #[test]
    fn spans_pack_into_blocks_lane_by_lane() {
        let slots: Vec<TetSlot> = (0..30).map(slot).collect();
        let mut p = LaneSlots::new(&slots, [0..10, 10..26, 26..30]);
        assert_eq!(p.spans, [0..2, 2..4, 4..5]);
        assert_eq!(p.blocks[1].count, 2);
        assert_eq!(LaneSlots::slot_range(&p.blocks[2..4]), 10..26);
        for b in &p.blocks {
            for k in 0..LANES {
                let Some(s) = slots
                    .get(b.first as usize + k)
                    .filter(|_| k < b.count as usize)
                else {
                    assert!(!b.is_live(k));
                    assert_eq!(b.dm_inv.map(|e| e[k]), Mat3::IDENTITY.to_cols_array());
                    assert_eq!(b.nodes.map(|j| j[k]), b.nodes.map(|j| j[0]));
                    continue;
                };
                assert_eq!(b.nodes.map(|j| j[k]), s.nodes);
                assert_eq!(b.dm_inv.map(|e| e[k]), s.terms.dm_inv.to_cols_array());
                assert_eq!(
                    (b.alpha_h[k], b.alpha_d[k]),
                    (s.terms.alpha_h, s.terms.alpha_d)
                );
                assert_eq!(b.is_live(k), s.live);
            }
        }
        p.set_live(3, true);
        p.set_live(17, false);
        assert!(p.blocks[0].is_live(3));
        assert!(!p.blocks[2].is_live(7));
    }
}
