//! One colour's tets projected eight at a time ([`super::rest_free_lanes`]): load a
//! [`LaneBlock`]'s terms lane by lane, read its tets' nodes into the lanes, project, write
//! the live ones back ([`super::lane_nodes`]).

use super::lane_nodes::NodeLanes;
use super::lane_slots::{LaneBlock, LaneSlots};
use super::lanes::{LANES, M3};
use super::rest_free_lanes::{TetLanes, project_rest_free_lanes};
use super::shared_nodes::SharedNodes;

/// Project the block's live tets (of one colour) and store their volume multipliers in
/// `lambdas`, which starts at slot `base`; lanes that are not live are left as they are.
///
/// # Safety
/// No other thread may touch these tets' nodes during the call (colouring).
#[inline(always)]
unsafe fn project_block<L: NodeLanes>(
    b: &LaneBlock,
    lambdas: &mut [f32],
    base: usize,
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    // SAFETY: the caller's contract.
    let (u, w) = unsafe { L::load_nodes(b, nodes, inv_mass) };
    let mut lanes = TetLanes {
        u,
        w,
        dm_inv: M3::load(&b.dm_inv),
        alpha_h: L::new(b.alpha_h),
        alpha_d: L::new(b.alpha_d),
        live: L::new(b.live),
    };
    let dl_h = project_rest_free_lanes(&mut lanes).to_array();
    // SAFETY: the caller's contract.
    unsafe { L::store_nodes(b, &lanes.u, nodes) };
    let first = b.first as usize - base;
    for k in (0..LANES).filter(|&k| b.is_live(k)) {
        lambdas[first + k] = dl_h[k];
    }
}

/// Project a run of one colour's blocks, block by block: in one AVX register per lane
/// value where `detect` is set and the CPU has AVX2 (checked at run time, so a portable
/// build uses it too), else with `wide`'s lanes at the build's instruction set. `lambdas`
/// holds the multipliers of the blocks' slots ([`LaneSlots::slot_range`]).
///
/// # Safety
/// As [`project_block`].
pub(super) unsafe fn project_run(
    blocks: &[LaneBlock],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
    detect: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if detect && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2; the rest is the caller's contract.
        return unsafe { project_run_avx2(blocks, lambdas, nodes, inv_mass) };
    }
    let _ = detect;
    // SAFETY: the caller's contract.
    unsafe { project_blocks::<wide::f32x8>(blocks, lambdas, nodes, inv_mass) }
}

/// [`project_blocks`] with [`super::lane_avx::Avx`] lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2; otherwise as [`project_block`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn project_run_avx2(
    blocks: &[LaneBlock],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    // SAFETY: the caller's contract.
    unsafe { project_blocks::<super::lane_avx::Avx>(blocks, lambdas, nodes, inv_mass) }
}

/// The run, block by block, compiled into its caller.
///
/// # Safety
/// As [`project_block`].
#[inline(always)]
unsafe fn project_blocks<L: NodeLanes>(
    blocks: &[LaneBlock],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    let base = LaneSlots::slot_range(blocks).start;
    for b in blocks {
        // SAFETY: the caller's contract.
        unsafe { project_block::<L>(b, lambdas, base, nodes, inv_mass) };
    }
}
