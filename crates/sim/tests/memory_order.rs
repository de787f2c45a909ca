//! Memory in the order it is used (issue 35, item 2; `xpbd/locality.rs`): the tets of each
//! colour stored by lowest node and packed eight to a SIMD block change no result.
//! Tets of one colour share no node, so the same bits come out, and the same tets tear,
//! in the coloured and the partitioned sweep, on one thread and on two.

mod common;

use glam::Vec3;
use incise_sim::xpbd::{CpuKernel, CpuSweep, TetOrder};
use incise_sim::{RawMesh, Solver, TetMesh};

/// The tearing bar's mesh (`common::tearing_bar`) with its tets listed in a scrambled
/// order, as a file might list them (the generator lists them in node order, which the
/// node order would leave as it is).
fn scrambled_bar() -> TetMesh {
    let mesh = common::tearing_bar_mesh();
    let n = mesh.tet_count();
    // 7919 is prime and does not divide the 4,320 tets: a permutation.
    let tets = (0..n).map(|t| mesh.tets[t * 7919 % n]).collect();
    let raw = RawMesh {
        positions: mesh.rest_positions.clone(),
        tets,
        warnings: Vec::new(),
        boundary_faces: None,
    };
    TetMesh::from_raw(raw)
        .expect("a permuted valid mesh is valid")
        .0
}

/// The tearing bar (`common::tearing_bar`), tets scrambled, stored in `order`.
fn bar(order: TetOrder, sweep: CpuSweep, kernel: CpuKernel, threads: usize) -> Solver {
    common::tearing_bar_on(scrambled_bar(), order, |p| {
        (p.cpu_sweep, p.cpu_kernel, p.threads) = (sweep, kernel, threads);
    })
}

/// The bits of each position.
fn bits(x: &[Vec3]) -> Vec<[u32; 3]> {
    x.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

/// Positions after each of `frames` frames, and every tet released by then, in the order
/// the frames released them.
fn run(mut s: Solver, frames: usize) -> (Vec<Vec<Vec3>>, Vec<u32>) {
    let mut released = Vec::new();
    let xs = (0..frames)
        .map(|_| {
            let before = s.cut().live().to_vec();
            s.step_frame().unwrap();
            let live = s.cut().live();
            released.extend(
                (0..live.len() as u32).filter(|&t| before[t as usize] && !live[t as usize]),
            );
            s.positions().to_vec()
        })
        .collect();
    (xs, released)
}

/// The node order moves the slots, and every sweep, kernel and thread count gives the
/// mesh order's bits, frame by frame, through the tear.
#[test]
fn the_memory_order_changes_no_result() {
    let cases = [
        (CpuSweep::Coloured, CpuKernel::Lanes, 1),
        (CpuSweep::Coloured, CpuKernel::Lanes, 2),
        (CpuSweep::Blocks, CpuKernel::Lanes, 1),
        (CpuSweep::Blocks, CpuKernel::Lanes, 2),
        (CpuSweep::Coloured, CpuKernel::Scalar, 1),
    ];
    for (sweep, kernel, threads) in cases {
        let mesh_order = bar(TetOrder::Mesh, sweep, kernel, threads);
        let local = bar(TetOrder::Nodes, sweep, kernel, threads);
        let moved = (mesh_order.slot_tets().iter())
            .zip(local.slot_tets())
            .filter(|(a, b)| a != b)
            .count();
        let slots = local.slot_tets().len();
        assert!(
            2 * moved > slots,
            "the node order should move most slots: {moved} of {slots}"
        );
        let (xa, ra) = run(mesh_order, 40);
        let (xb, rb) = run(local, 40);
        assert!(!ra.is_empty(), "the pull should tear the bar");
        let first = ra.iter().zip(&rb).position(|(a, b)| a != b);
        assert!(
            ra == rb,
            "{sweep:?}, {kernel:?}, {threads} threads: {} tets torn against {}, the first \
             difference at release {first:?}",
            rb.len(),
            ra.len()
        );
        for (f, (a, b)) in xa.iter().zip(&xb).enumerate() {
            assert!(
                bits(a) == bits(b),
                "{sweep:?}, {kernel:?}, {threads} threads, frame {f}: {:e} m apart",
                common::worst_gap(a, b)
            );
        }
    }
}
