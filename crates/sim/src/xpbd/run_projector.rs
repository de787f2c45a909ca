//! One span of a sweep projected: a colour (coloured sweep) or one group's run of a colour
//! (partitioned sweep), tets that share no node, with the solver's kernel: the SIMD lanes
//! over the span's packed blocks ([`LaneSlots`]), or the scalar reference over its slots.

use std::ops::Range;

use rayon::prelude::*;

use super::lane_pass;
use super::lane_slots::{LaneBlock, LaneSlots};
use super::lanes::LANES;
use super::neo_hookean::{ConstraintPair, TetProjection};
use super::shared_nodes::SharedNodes;
use super::tet_constraint::project_tet;
use super::tet_slot::TetSlot;
use super::{CpuKernel, SolverParams};

/// Tets per rayon task: large enough to amortise scheduling, small enough to balance.
pub(crate) const CHUNK: usize = 256;

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
    inv_mass: &'a [f32],
    slots: &'a [TetSlot],
    /// The packed blocks, and whether to detect AVX2, when the lanes project.
    lanes: Option<(&'a LaneSlots, bool)>,
    mode: TetProjection,
    pair: ConstraintPair,
}

impl<'a> RunProjector<'a> {
    /// Whether `params` project with the SIMD lanes (the rest-free coupled pair with a
    /// lane kernel), and if so whether with run-time AVX2 detection.
    pub fn lane_kernel(params: &SolverParams) -> Option<bool> {
        let lanes = match params.cpu_kernel {
            CpuKernel::Lanes => Some(true),
            CpuKernel::PortableLanes => Some(false),
            CpuKernel::Scalar => None,
        };
        lanes.filter(|_| {
            params.constraints == ConstraintPair::RestFree
                && params.projection == TetProjection::Coupled
        })
    }

    /// The projector of `params`' kernel and pair over `slots`, eight tets at a time in
    /// SIMD lanes from `packed` where the kernel is the lanes', or one by one.
    pub fn of(
        params: &SolverParams,
        inv_mass: &'a [f32],
        slots: &'a [TetSlot],
        packed: Option<&'a LaneSlots>,
    ) -> Self {
        RunProjector {
            inv_mass,
            slots,
            lanes: packed.zip(Self::lane_kernel(params)),
            mode: params.projection,
            pair: params.constraints,
        }
    }

    /// Project span `k` (slots `range`, packed span `k`), in tasks of [`CHUNK`] tets on
    /// the current pool when `parallel`, and store the volume multipliers.
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
        parallel: bool,
    ) {
        if let Some((packed, detect)) = self.lanes {
            let blocks = &packed.blocks[packed.spans[k].clone()];
            // SAFETY: a colour's tets share no node and each task has its own blocks,
            // whose slots are their own; the rest is the caller's contract.
            let run = |b: &[LaneBlock]| unsafe {
                let l = lambdas.run(LaneSlots::slot_range(b));
                lane_pass::project_run(b, l, nodes, self.inv_mass, detect)
            };
            if parallel && blocks.len() > CHUNK / LANES {
                blocks.par_chunks(CHUNK / LANES).for_each(run);
            } else {
                run(blocks);
            }
            return;
        }
        // SAFETY: as above, each task its own range of slots.
        let run = |r: Range<usize>| unsafe { self.scalar(r.clone(), lambdas.run(r), nodes) };
        if parallel && range.len() > CHUNK {
            let starts: Vec<usize> = range.clone().step_by(CHUNK).collect();
            starts
                .par_iter()
                .for_each(|&s| run(s..(s + CHUNK).min(range.end)));
        } else {
            run(range);
        }
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
            let mut p = idx.map(|i| unsafe { nodes.get(i) });
            let w = idx.map(|i| self.inv_mass[i as usize]);
            *lambda = project_tet(&mut p, &w, &slot.terms, self.mode, self.pair);
            for k in 0..4 {
                // SAFETY: as above.
                unsafe { nodes.set(idx[k], p[k]) };
            }
        }
    }
}
