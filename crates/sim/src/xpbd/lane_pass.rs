//! One colour's tets projected eight at a time ([`super::rest_free_lanes`]): gather the
//! tets' nodes and terms into lanes, project, scatter the live ones back.

use glam::{Mat3, Vec3};

use super::lanes::{LANES, Lane, M3, V3};
use super::rest_free_lanes::{TetLanes, project_rest_free_lanes};
use super::shared_nodes::SharedNodes;
use super::tet_slot::TetSlot;

/// Project `slots` (tets of one colour, at most [`LANES`]) and store their volume
/// multipliers in `lambdas`; tets that are not live are left as they are.
///
/// # Safety
/// No other thread may touch these tets' nodes during the call (colouring).
#[inline(always)]
unsafe fn project_block<L: Lane>(
    slots: &[TetSlot],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    debug_assert!(slots.len() <= LANES);
    let mut u = [[Vec3::ZERO; LANES]; 4];
    let mut w = [[0.0f32; LANES]; 4];
    let mut dm_inv = [Mat3::IDENTITY; LANES];
    let (mut alpha_h, mut alpha_d) = ([1.0f32; LANES], [1.0f32; LANES]);
    let mut live = [0.0f32; LANES];
    for (k, s) in slots.iter().enumerate().filter(|(_, s)| s.live) {
        for j in 0..4 {
            // SAFETY: the caller's contract.
            u[j][k] = unsafe { nodes.get(s.nodes[j]) };
            w[j][k] = inv_mass[s.nodes[j] as usize];
        }
        dm_inv[k] = s.terms.dm_inv;
        (alpha_h[k], alpha_d[k]) = (s.terms.alpha_h, s.terms.alpha_d);
        live[k] = f32::from_bits(u32::MAX);
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
        dm_inv: M3::gather(&dm_inv),
        alpha_h: L::new(alpha_h),
        alpha_d: L::new(alpha_d),
        live: L::new(live),
    };
    let dl_h = project_rest_free_lanes(&mut lanes).to_array();
    // Each position stored once, then read lane by lane.
    let u = [
        lanes.u[0].to_arrays(),
        lanes.u[1].to_arrays(),
        lanes.u[2].to_arrays(),
        lanes.u[3].to_arrays(),
    ];
    for (k, s) in slots.iter().enumerate().filter(|(_, s)| s.live) {
        for (node, u) in s.nodes.iter().zip(&u) {
            // SAFETY: the caller's contract.
            unsafe { nodes.set(*node, Vec3::new(u[0][k], u[1][k], u[2][k])) };
        }
        lambdas[k] = dl_h[k];
    }
}

/// Project a run of one colour's slots, block by block: in one AVX register per lane
/// value where `detect` is set and the CPU has AVX2 (checked at run time, so a portable
/// build uses it too), else with `wide`'s lanes at the build's instruction set.
///
/// # Safety
/// As [`project_block`].
pub(super) unsafe fn project_run(
    slots: &[TetSlot],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
    detect: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if detect && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2; the rest is the caller's contract.
        return unsafe { project_run_avx2(slots, lambdas, nodes, inv_mass) };
    }
    let _ = detect;
    // SAFETY: the caller's contract.
    unsafe { project_blocks::<wide::f32x8>(slots, lambdas, nodes, inv_mass) }
}

/// [`project_blocks`] with [`super::lane_avx::Avx`] lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2; otherwise as [`project_block`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn project_run_avx2(
    slots: &[TetSlot],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    // SAFETY: the caller's contract.
    unsafe { project_blocks::<super::lane_avx::Avx>(slots, lambdas, nodes, inv_mass) }
}

/// The run, block by block, compiled into its caller.
///
/// # Safety
/// As [`project_block`].
#[inline(always)]
unsafe fn project_blocks<L: Lane>(
    slots: &[TetSlot],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    inv_mass: &[f32],
) {
    for (s, l) in slots.chunks(LANES).zip(lambdas.chunks_mut(LANES)) {
        // SAFETY: the caller's contract.
        unsafe { project_block::<L>(s, l, nodes, inv_mass) };
    }
}
