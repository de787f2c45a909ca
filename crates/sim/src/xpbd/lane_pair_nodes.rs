//! Two lane blocks' nodes into and out of sixteen AVX-512 lanes (issue 35, item 3): the
//! records of lanes `k` and `k + 4` of the first block and of the second put in the four
//! 128-bit quarters of one register, and four such registers transposed quarter by
//! quarter into a node row's `x, y, z, w` in the order [`Avx512::join`] gives (the first
//! block's lanes 0–7, then the second's); written back by the same transpose, whole
//! records, live lanes only. The same values in every lane as two blocks read by the AVX
//! way ([`super::lane_nodes`]) and joined, with half the loads' inserts and no join.

use std::arch::x86_64::*;

use super::lane_avx::Avx;
use super::lane_avx512::Avx512;
use super::lane_nodes::{masked_row, rows_below};
use super::lane_slots::LaneBlock;
use super::lanes::{LANES, Lane, V3};
use super::node_records::NodeRecord;
use super::shared_nodes::SharedNodes;

/// The records of `lo`'s lanes `k`, `k + 4` and `hi`'s lanes `k`, `k + 4`, quarter by
/// quarter.
///
/// # Safety
/// Every index is a record of `base`'s array; AVX-512F is present.
#[inline(always)]
unsafe fn quarters(
    base: *const NodeRecord,
    lo: &[u32; LANES],
    hi: &[u32; LANES],
    k: usize,
) -> __m512 {
    // SAFETY: the caller's contract; a record is 16 bytes, 16-aligned.
    unsafe {
        let v = _mm512_castps128_ps512(_mm_load_ps(base.add(lo[k] as usize) as *const f32));
        let v = _mm512_insertf32x4::<1>(v, _mm_load_ps(base.add(lo[k + 4] as usize) as _));
        let v = _mm512_insertf32x4::<2>(v, _mm_load_ps(base.add(hi[k] as usize) as _));
        _mm512_insertf32x4::<3>(v, _mm_load_ps(base.add(hi[k + 4] as usize) as _))
    }
}

/// Four rows of four values in each quarter, as four columns (its own inverse).
///
/// # Safety
/// AVX-512F is present.
#[inline(always)]
unsafe fn transpose(r0: __m512, r1: __m512, r2: __m512, r3: __m512) -> [__m512; 4] {
    // SAFETY: the caller's contract.
    unsafe {
        let t0 = _mm512_unpacklo_ps(r0, r1);
        let t1 = _mm512_unpackhi_ps(r0, r1);
        let t2 = _mm512_unpacklo_ps(r2, r3);
        let t3 = _mm512_unpackhi_ps(r2, r3);
        [
            _mm512_shuffle_ps::<0x44>(t0, t2),
            _mm512_shuffle_ps::<0xEE>(t0, t2),
            _mm512_shuffle_ps::<0x44>(t1, t3),
            _mm512_shuffle_ps::<0xEE>(t1, t3),
        ]
    }
}

/// Node row `j` of both blocks: displacements and inverse masses, zero where `live` is
/// clear.
///
/// # Safety
/// As [`quarters`].
#[inline(always)]
unsafe fn read_row(
    base: *const NodeRecord,
    (lo, hi): (&LaneBlock, &LaneBlock),
    j: usize,
    live: Avx512,
) -> (V3<Avx512>, Avx512) {
    let (a, b) = (&lo.nodes[j], &hi.nodes[j]);
    // SAFETY: the caller's contract.
    let [x, y, z, w] = unsafe {
        transpose(
            quarters(base, a, b, 0),
            quarters(base, a, b, 1),
            quarters(base, a, b, 2),
            quarters(base, a, b, 3),
        )
    };
    let raw = [
        Avx512::from_raw(x),
        Avx512::from_raw(y),
        Avx512::from_raw(z),
        Avx512::from_raw(w),
    ];
    masked_row(raw, live)
}

/// The blocks' nodes in sixteen lanes (`lo`'s in 0–7, `hi`'s in 8–15): displacements and
/// inverse masses, zero where a lane is not live.
///
/// # Safety
/// No other thread may write these nodes during the call (colouring); AVX-512F is present.
#[inline(always)]
pub(super) unsafe fn load_pair(
    lo: &LaneBlock,
    hi: &LaneBlock,
    nodes: &SharedNodes,
) -> ([V3<Avx512>; 4], [Avx512; 4]) {
    assert!(
        rows_below(&lo.nodes, nodes.len()) && rows_below(&hi.nodes, nodes.len()),
        "a lane block names a node past the mesh's"
    );
    let base = nodes.as_ptr() as *const NodeRecord;
    let live = Avx512::join(Avx::new(lo.live), Avx::new(hi.live));
    // SAFETY: every index is in bounds (checked); the rest is the caller's contract.
    unsafe {
        let r0 = read_row(base, (lo, hi), 0, live);
        let r1 = read_row(base, (lo, hi), 1, live);
        let r2 = read_row(base, (lo, hi), 2, live);
        let r3 = read_row(base, (lo, hi), 3, live);
        ([r0.0, r1.0, r2.0, r3.0], [r0.1, r1.1, r2.1, r3.1])
    }
}

/// Write lanes 0–7 of `u` to `lo`'s nodes and lanes 8–15 to `hi`'s, for each live lane:
/// whole records, with the inverse masses `w` that [`load_pair`] read.
///
/// # Safety
/// No other thread may read or write these nodes during the call (colouring); AVX-512F
/// is present.
#[inline(always)]
pub(super) unsafe fn store_pair(
    lo: &LaneBlock,
    hi: &LaneBlock,
    u: &[V3<Avx512>; 4],
    w: &[Avx512; 4],
    nodes: &SharedNodes,
) {
    assert!(
        rows_below(&lo.nodes, nodes.len()) && rows_below(&hi.nodes, nodes.len()),
        "a lane block names a node past the mesh's"
    );
    let base = nodes.as_ptr() as *mut f32;
    // SAFETY: in bounds (checked); the rest is the caller's contract.
    unsafe {
        let live = _mm256_movemask_ps(Avx::new(lo.live).raw()) as u32
            | (_mm256_movemask_ps(Avx::new(hi.live).raw()) as u32) << LANES;
        for j in 0..4 {
            let (a, b) = (&lo.nodes[j], &hi.nodes[j]);
            let v = &u[j];
            let rows = transpose(v.x.raw(), v.y.raw(), v.z.raw(), w[j].raw());
            for (k, r) in rows.iter().enumerate() {
                // Lane k of `lo`, k + 4 of `lo`, k of `hi`, k + 4 of `hi`.
                let to = [a[k], a[k + 4], b[k], b[k + 4]];
                let on = [k, k + 4, LANES + k, LANES + k + 4].map(|l| live & 1 << l != 0);
                if on[0] {
                    put::<0>(base, to[0], *r);
                }
                if on[1] {
                    put::<1>(base, to[1], *r);
                }
                if on[2] {
                    put::<2>(base, to[2], *r);
                }
                if on[3] {
                    put::<3>(base, to[3], *r);
                }
            }
        }
    }
}

/// Quarter `Q` of `r` as node `node`'s record.
///
/// # Safety
/// `node` is a record of `base`'s array; AVX-512F is present.
#[inline(always)]
unsafe fn put<const Q: i32>(base: *mut f32, node: u32, r: __m512) {
    // SAFETY: the caller's contract; a record is 16 bytes, 16-aligned.
    unsafe { _mm_store_ps(base.add(4 * node as usize), _mm512_extractf32x4_ps::<Q>(r)) }
}
