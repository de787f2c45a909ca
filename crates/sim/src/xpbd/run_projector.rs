//! One span of a sweep projected: a colour (coloured sweep) or one group's run of a colour
//! (partitioned sweep), tets that share no node, with the solver's kernel: the SIMD lanes
//! over the span's packed blocks ([`LaneSlots`]), or the scalar reference over its slots.

use std::ops::Range;

use super::lane_pass::{self, Simd};
use super::lane_slots::LaneSlots;
use super::neo_hookean::{ConstraintPair, TetProjection};
use super::shared_nodes::SharedNodes;
use super::tet_constraint::project_tet;
use super::tet_slot::TetSlot;
use super::{CpuKernel, SolverParams};
use crate::thread_team::share;

/// The volume multipliers, written by several tasks at once.
pub(crate) struct SharedLambdas(*mut f32);

// SAFETY: each task writes only its own spans' disjoint slots (`RunProjector::span`).
unsafe impl Sync for SharedLambdas {}

impl SharedLambdas {
    /// A view of `lambdas` for the tasks of one sweep.
    pub fn new(lambdas: &mut [f32]) -> Self {
        SharedLambdas(lambdas.as_mut_ptr())
    }

    /// The multipliers of slots `r`.
    ///
    /// # Safety
    /// `r` lies inside the array, and no other task touches these slots meanwhile.
    unsafe fn run<'a>(&self, r: Range<usize>) -> &'a mut [f32] {
        // SAFETY: the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.0.add(r.start), r.len()) }
    }
}

/// Projects spans of tets with the solver's kernel and constraint pair.
pub(crate) struct RunProjector<'a> {
    slots: &'a [TetSlot],
    /// The packed blocks, and the widest instructions to look for, when the lanes project.
    lanes: Option<(&'a LaneSlots, Simd)>,
    mode: TetProjection,
    pair: ConstraintPair,
}

impl<'a> RunProjector<'a> {
    /// Whether `params` project with the SIMD lanes (the rest-free coupled pair with a
    /// lane kernel), and if so the widest instructions to look for at run time.
    pub fn lane_kernel(params: &SolverParams) -> Option<Simd> {
        let lanes = match params.cpu_kernel {
            CpuKernel::Lanes => Some(Simd::Widest),
            CpuKernel::Avx2Lanes => Some(Simd::Avx2),
            CpuKernel::PortableLanes => Some(Simd::Build),
            CpuKernel::Scalar => None,
        };
        lanes.filter(|_| {
            params.constraints == ConstraintPair::RestFree
                && params.projection == TetProjection::Coupled
        })
    }

    /// The projector of `params`' kernel and pair over `slots`, eight tets at a time in
    /// SIMD lanes from `packed` where the kernel is the lanes', or one by one.
    pub fn of(params: &SolverParams, slots: &'a [TetSlot], packed: Option<&'a LaneSlots>) -> Self {
        RunProjector {
            slots,
            lanes: packed.zip(Self::lane_kernel(params)),
            mode: params.projection,
            pair: params.constraints,
        }
    }

    /// Project part `p` of `parts` contiguous parts of span `k` (slots `range`, packed
    /// span `k`), and store the volume multipliers. The parts together are the span; any
    /// split gives the same bits, as a span's tets share no node.
    ///
    /// # Safety
    /// No other task may touch these tets' nodes or slots during the call; `range` and
    /// span `k` are the same tets of one colour.
    pub unsafe fn span(
        &self,
        k: usize,
        range: Range<usize>,
        lambdas: &SharedLambdas,
        nodes: &SharedNodes,
        (p, parts): (usize, usize),
    ) {
        if let Some((packed, simd)) = self.lanes {
            let span = packed.spans[k].clone();
            let blocks = &packed.blocks[span.start..span.end][share(span.len(), p, parts)];
            // SAFETY: a colour's tets share no node and each part has its own blocks,
            // whose slots are their own; the rest is the caller's contract.
            unsafe {
                let l = lambdas.run(LaneSlots::slot_range(blocks));
                lane_pass::project_run(blocks, l, nodes, simd)
            };
            return;
        }
        let mine = share(range.len(), p, parts);
        let r = range.start + mine.start..range.start + mine.end;
        // SAFETY: as above, each part its own range of slots.
        unsafe { self.scalar(r.clone(), lambdas.run(r), nodes) };
    }

    /// Project slots `r` one by one with the scalar reference.
    ///
    /// # Safety
    /// No other thread may touch these tets' nodes during the call.
    unsafe fn scalar(&self, r: Range<usize>, lambdas: &mut [f32], nodes: &SharedNodes) {
        let slots = &self.slots[r];
        for (slot, lambda) in slots.iter().zip(lambdas).filter(|(s, _)| s.live) {
            let idx = slot.nodes;
            // SAFETY: the caller's contract.
            let read = idx.map(|i| unsafe { nodes.get(i) });
            let (mut p, w) = (read.map(|r| r.0), read.map(|r| r.1));
            *lambda = project_tet(&mut p, &w, &slot.terms, self.mode, self.pair);
            for k in 0..4 {
                // SAFETY: as above.
                unsafe { nodes.set(idx[k], p[k]) };
            }
        }
    }
}
