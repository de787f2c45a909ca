//! One colour's tets projected eight (or sixteen) at a time
//! ([`super::rest_free_lanes`]): load a [`LaneBlock`]'s terms lane by lane, read its tets'
//! nodes into the lanes, project, write the live ones back ([`super::lane_nodes`]).

#[cfg(target_arch = "x86_64")]
use super::lane_avx::Avx;
use super::lane_nodes::NodeLanes;
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
unsafe fn project_block<L: NodeLanes>(
    b: &LaneBlock,
    lambdas: &mut [f32],
    base: usize,
    nodes: &SharedNodes,
) {
    // SAFETY: the caller's contract.
    let mut lanes = unsafe { block_lanes::<L>(b, nodes) };
    let dl_h = project_rest_free_lanes(&mut lanes);
    // SAFETY: the caller's contract.
    unsafe { finish_block(b, (&lanes.u, &lanes.w), dl_h, lambdas, base, nodes) };
}

/// The block's tets in lanes: their terms and their nodes' values.
///
/// # Safety
/// As [`project_block`].
#[inline(always)]
unsafe fn block_lanes<L: NodeLanes>(b: &LaneBlock, nodes: &SharedNodes) -> TetLanes<L> {
    // SAFETY: the caller's contract.
    let (u, w) = unsafe { L::load_nodes(b, nodes) };
    TetLanes {
        u,
        w,
        dm_inv: M3::load(&b.dm_inv),
        alpha_h: L::new(b.alpha_h),
        alpha_d: L::new(b.alpha_d),
        live: L::new(b.live),
    }
}

/// Write the block's projected displacements `u` (beside the inverse masses `w` it read)
/// and multipliers `dl_h` (live lanes only).
///
/// # Safety
/// As [`project_block`].
#[inline(always)]
unsafe fn finish_block<L: NodeLanes>(
    b: &LaneBlock,
    (u, w): (&[V3<L>; 4], &[L; 4]),
    dl_h: L,
    lambdas: &mut [f32],
    base: usize,
    nodes: &SharedNodes,
) {
    // SAFETY: the caller's contract.
    unsafe { L::store_nodes(b, u, w, nodes) };
    store_multipliers(b, dl_h, lambdas, base);
}

/// Store the block's live lanes' multipliers `dl_h` in `lambdas` (which starts at slot
/// `base`).
#[inline(always)]
fn store_multipliers<L: Lane>(b: &LaneBlock, dl_h: L, lambdas: &mut [f32], base: usize) {
    let dl_h = dl_h.to_array();
    let first = b.first as usize - base;
    // Every lane live (padding lanes never are, so a full block).
    if L::new(b.live).bits() == L::ALL {
        lambdas[first..first + LANES].copy_from_slice(&dl_h);
        return;
    }
    for k in (0..LANES).filter(|&k| b.is_live(k)) {
        lambdas[first + k] = dl_h[k];
    }
}

/// The widest instructions the lanes look for at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Simd {
    /// AVX-512F, else AVX2, else the build's own.
    Widest,
    /// AVX2, else the build's own.
    Avx2,
    /// The build's own (`wide`'s lanes; SSE2 in the portable x86-64 build).
    Build,
}

/// Project a run of one colour's blocks: two blocks at a time in one AVX-512 register per
/// lane value where `simd` allows it and the CPU has AVX-512F, block by block in one AVX
/// register where it has AVX2 (both checked at run time, so a portable build uses them
/// too), else with `wide`'s lanes at the build's instruction set. Each tet's bits are
/// the same on all three. `lambdas` holds the multipliers of the blocks' slots
/// ([`LaneSlots::slot_range`]).
///
/// # Safety
/// As [`project_block`].
pub(super) unsafe fn project_run(
    blocks: &[LaneBlock],
    lambdas: &mut [f32],
    nodes: &SharedNodes,
    simd: Simd,
) {
    // The AVX-512 lanes need Rust 1.89 (build.rs); before it the AVX ones serve.
    #[cfg(all(target_arch = "x86_64", incise_avx512))]
    if simd == Simd::Widest && std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU has AVX-512F (and so AVX2); the rest is the caller's contract.
        return unsafe { project_run_avx512(blocks, lambdas, nodes) };
    }
    #[cfg(target_arch = "x86_64")]
    if simd != Simd::Build && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2; the rest is the caller's contract.
        return unsafe { project_run_avx2(blocks, lambdas, nodes) };
    }
    let _ = simd;
    // SAFETY: the caller's contract.
    unsafe { project_blocks::<wide::f32x8>(blocks, lambdas, nodes) }
}

/// [`project_blocks`] with [`super::lane_avx::Avx`] lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2; otherwise as [`project_block`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn project_run_avx2(blocks: &[LaneBlock], lambdas: &mut [f32], nodes: &SharedNodes) {
    // SAFETY: the caller's contract.
    unsafe { project_blocks::<Avx>(blocks, lambdas, nodes) }
}

/// The run two blocks at a time in [`super::lane_avx512::Avx512`] lanes (the blocks of a
/// run are of one colour and share no node, so their order does not matter), compiled
/// for AVX-512F; an odd last block in [`Avx`] lanes.
///
/// # Safety
/// The CPU must have AVX-512F; otherwise as [`project_block`].
#[cfg(all(target_arch = "x86_64", incise_avx512))]
#[allow(clippy::incompatible_msrv)]
#[target_feature(enable = "avx,avx2,avx512f")]
unsafe fn project_run_avx512(blocks: &[LaneBlock], lambdas: &mut [f32], nodes: &SharedNodes) {
    use super::lane_avx512::pair_tets;
    use super::lane_pair_nodes::{load_pair, store_pair};
    let base = LaneSlots::slot_range(blocks).start;
    let mut pairs = blocks.chunks_exact(2);
    for pair in &mut pairs {
        let (lo, hi) = (&pair[0], &pair[1]);
        // SAFETY: the caller's contract (the blocks are of one colour: no node in both);
        // the CPU has AVX-512F.
        unsafe {
            let mut lanes = pair_tets(lo, hi, load_pair(lo, hi, nodes));
            let (dl_lo, dl_hi) = project_rest_free_lanes(&mut lanes).split();
            store_pair(lo, hi, &lanes.u, &lanes.w, nodes);
            store_multipliers(lo, dl_lo, lambdas, base);
            store_multipliers(hi, dl_hi, lambdas, base);
        }
    }
    for b in pairs.remainder() {
        // SAFETY: the caller's contract.
        unsafe { project_block::<Avx>(b, lambdas, base, nodes) };
    }
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
) {
    let base = LaneSlots::slot_range(blocks).start;
    for b in blocks {
        // SAFETY: the caller's contract.
        unsafe { project_block::<L>(b, lambdas, base, nodes) };
    }
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, Vec3};

    use super::*;
    use crate::xpbd::neo_hookean::{TetProjection, TetTerms};
    use crate::xpbd::node_records::NodeRecord;
    use crate::xpbd::rest_free::project_rest_free;
    use crate::xpbd::tet_slot::TetSlot;

    /// 37 tets on disjoint nodes (four full blocks and one of five: two pairs and an odd
    /// block), strained from nothing to inverted, some flattened below J_MIN, some without
    /// a volume constraint, tets 4 and 21 not live.
    fn tet_slots() -> Vec<TetSlot> {
        (0..37u32)
            .map(|s| {
                let f = (s % 10) as f32;
                TetSlot {
                    nodes: [4 * s, 4 * s + 1, 4 * s + 2, 4 * s + 3],
                    terms: TetTerms {
                        dm_inv: Mat3::from_diagonal(Vec3::new(1.0, 1.1, 0.9 + 0.01 * f)),
                        alpha_h: if s % 5 == 3 {
                            f32::INFINITY
                        } else {
                            0.2 + 0.01 * f
                        },
                        alpha_d: 0.3 + 0.05 * f,
                        gamma: 1.0,
                    },
                    live: s != 4 && s != 21,
                }
            })
            .collect()
    }

    /// [`tet_slots`] in one span.
    fn slots() -> LaneSlots {
        LaneSlots::new(&tet_slots(), std::iter::once(0..37))
    }

    /// Node `i`'s inverse mass.
    fn inv_mass(i: usize) -> f32 {
        1.0 / (1.0 + (i % 5) as f32)
    }

    /// Node `i`'s displacement from rest: tet `i / 4` strained by its number.
    fn displacement(i: usize) -> Vec3 {
        let (s, j) = (i / 4, i % 4);
        let a = (s % 7) as f32 * 0.04;
        match (s % 9, j) {
            (6, 3) => Vec3::new(0.0, 0.0, -0.95),
            (7, 3) => Vec3::new(0.1, 0.0, -1.4),
            (6 | 7, _) => Vec3::ZERO,
            _ => Vec3::new(0.3 * a * j as f32, -0.1 * a, 0.05 * a * (j as f32 - 1.5)),
        }
    }

    /// The bits of every node and multiplier after `project` ran the whole run.
    fn run(
        project: unsafe fn(&[LaneBlock], &mut [f32], &SharedNodes),
    ) -> (Vec<[u32; 3]>, Vec<u32>) {
        let slots = slots();
        let mut records: Vec<NodeRecord> = (0..4 * 37)
            .map(|i| NodeRecord {
                u: displacement(i),
                w: inv_mass(i),
            })
            .collect();
        let mut lambdas = vec![-1.0f32; LaneSlots::slot_range(&slots.blocks).len()];
        let shared = SharedNodes::new(&mut records);
        // SAFETY: one thread; the run is one colour (disjoint nodes).
        unsafe { project(&slots.blocks, &mut lambdas, &shared) };
        for (i, r) in records.iter().enumerate() {
            assert_eq!(
                r.w.to_bits(),
                inv_mass(i).to_bits(),
                "node {i}'s mass written"
            );
        }
        let nodes = records
            .iter()
            .map(|r| r.u.to_array().map(f32::to_bits))
            .collect();
        (nodes, lambdas.iter().map(|l| l.to_bits()).collect())
    }

    /// Each live tet's nodes and multiplier as the scalar reference projects them (the
    /// tets share no node, so one at a time), the dead tets' nodes as they were.
    fn reference() -> (Vec<Vec3>, Vec<f32>) {
        let mut x: Vec<Vec3> = (0..4 * 37).map(displacement).collect();
        let mut lambdas = vec![-1.0f32; 37];
        for (s, slot) in tet_slots().iter().enumerate().filter(|(_, t)| t.live) {
            let at = slot.nodes.map(|i| i as usize);
            let mut p = at.map(|i| x[i]);
            let w = at.map(inv_mass);
            lambdas[s] = project_rest_free(&mut p, &w, &slot.terms, TetProjection::Coupled);
            for (i, p) in at.into_iter().zip(p) {
                x[i] = p;
            }
        }
        (x, lambdas)
    }

    /// `project`'s run against the scalar reference: nodes within 2e-6 (the lanes' `ln`
    /// rounds apart), multipliers within 2e-6 relative, the dead tets' left as they were.
    fn check_against_reference(
        project: unsafe fn(&[LaneBlock], &mut [f32], &SharedNodes),
        what: &str,
    ) {
        let (nodes, lambdas) = run(project);
        let (want_x, want_l) = reference();
        for (i, (got, want)) in nodes.iter().zip(&want_x).enumerate() {
            let got = Vec3::from_array(got.map(f32::from_bits));
            assert!(
                got.abs_diff_eq(*want, 2e-6),
                "{what}: node {i}: {got} vs {want}"
            );
        }
        for (s, (got, want)) in lambdas.iter().zip(&want_l).enumerate() {
            let got = f32::from_bits(*got);
            let tol = 2e-6 * (1.0 + want.abs());
            assert!(
                (got - want).abs() <= tol,
                "{what}: tet {s}: λ {got} vs {want}"
            );
        }
    }

    /// The whole-run paths against the scalar reference: `wide`'s lanes and the AVX ones
    /// (where the CPU has AVX2), block by block, padding and dead lanes included; the
    /// every-lane-live blocks' multipliers are written as one slice. Broken on purpose
    /// once (that slice written with two lanes swapped): fails.
    #[test]
    fn lane_runs_project_what_the_scalar_reference_projects() {
        unsafe fn portable(b: &[LaneBlock], l: &mut [f32], n: &SharedNodes) {
            // SAFETY: the caller's contract.
            unsafe { project_blocks::<wide::f32x8>(b, l, n) }
        }
        check_against_reference(portable, "wide");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            check_against_reference(project_run_avx2, "AVX2");
        }
    }

    /// Two blocks in one AVX-512 register give every tet the bits one block in an AVX
    /// register gives it: the nodes, the multipliers, the dead tets and padding left as
    /// they were; where the CPU has AVX-512F. Broken on purpose once (the pair's
    /// multipliers written to each other's block): fails.
    #[cfg(all(target_arch = "x86_64", incise_avx512))]
    #[test]
    fn avx512_pairs_project_what_avx_blocks_project() {
        if !std::arch::is_x86_feature_detected!("avx512f") {
            eprintln!("skipping: no AVX-512F");
            return;
        }
        let (avx_nodes, avx_lambdas) = run(project_run_avx2);
        let (wide_nodes, wide_lambdas) = run(project_run_avx512);
        let at_rest: Vec<[u32; 3]> = (0..4 * 37)
            .map(|i| displacement(i).to_array().map(f32::to_bits))
            .collect();
        let moved = (0..4 * 37).filter(|&i| avx_nodes[i] != at_rest[i]).count();
        assert!(moved > 80, "only {moved} nodes moved");
        for dead in [4usize, 21] {
            assert_eq!(
                avx_nodes[4 * dead..4 * dead + 4],
                at_rest[4 * dead..4 * dead + 4]
            );
        }
        assert_eq!(wide_nodes, avx_nodes, "nodes");
        assert_eq!(wide_lambdas, avx_lambdas, "multipliers");
    }
}
