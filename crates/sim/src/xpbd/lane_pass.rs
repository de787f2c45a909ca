//! One colour's tets projected eight at a time ([`super::rest_free_lanes`]): load a
//! [`LaneBlock`]'s terms lane by lane, gather its tets' nodes, project, scatter the live
//! ones back.

use glam::Vec3;

use super::lane_slots::{LaneBlock, LaneSlots};
use super::lanes::{LANES, Lane, M3, V3};
use super::rest_free_lanes::{TetLanes, project_rest_free_lanes};
use super::shared_nodes::SharedNodes;

/// Project the block's live tets (of one colour) and store their volume multipliers in
/// `lambdas`, which starts at slot `base`; lanes that are not live are left as they are.
///
/// # Safety
/// No other thread may touch these tets' nodes during the call (colouring).
#[inline(always)]
unsafe fn project_block<L: Lane>(
    b: &LaneBlock,
    lambdas: &mut [f32],
    base: usize,
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    let mut u = [[Vec3::ZERO; LANES]; 4];
    let mut w = [[0.0f32; LANES]; 4];
    for k in (0..LANES).filter(|&k| b.is_live(k)) {
        for j in 0..4 {
            let i = b.nodes[j][k];
            // SAFETY: the caller's contract.
            u[j][k] = unsafe { nodes.get(i) };
            w[j][k] = inv_mass[i as usize];
        }
    }
    let mut lanes = TetLanes {
        // Written out, not `map`: an out-of-line `map` would be compiled without the
        // caller's AVX and call each intrinsic.
        u: [
            V3::gather(&u[0]),
            V3::gather(&u[1]),
            V3::gather(&u[2]),
            V3::gather(&u[3]),
        ],
        w: [L::new(w[0]), L::new(w[1]), L::new(w[2]), L::new(w[3])],
        dm_inv: M3::load(&b.dm_inv),
        alpha_h: L::new(b.alpha_h),
        alpha_d: L::new(b.alpha_d),
        live: L::new(b.live),
    };
    let dl_h = project_rest_free_lanes(&mut lanes).to_array();
    // Each position stored once, then read lane by lane.
    let u = [
        lanes.u[0].to_arrays(),
        lanes.u[1].to_arrays(),
        lanes.u[2].to_arrays(),
        lanes.u[3].to_arrays(),
    ];
    let first = b.first as usize - base;
    for k in (0..LANES).filter(|&k| b.is_live(k)) {
        for (j, u) in u.iter().enumerate() {
            // SAFETY: the caller's contract.
            unsafe { nodes.set(b.nodes[j][k], Vec3::new(u[0][k], u[1][k], u[2][k])) };
        }
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
unsafe fn project_blocks<L: Lane>(
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
