//! Node values into and out of the lanes (issue 35, item 3): an XPBD block's four nodes'
//! displacements and inverse masses of eight tets read from the sweep's node records
//! ([`NodeRecord`]) into lane registers before the projection and the displacements
//! written back after it; and any eight nodes of a slice read by index (`read_vec3s`: the
//! implicit scheme's tet evaluation and product).
//!
//! The generic way reads lane by lane into arrays and loads those; the AVX one reads each
//! node's record with one 16-byte load, two records to a register, and transposes four
//! such registers into `x, y, z, w` (no store of eight scalars followed by one wide load,
//! which the CPU cannot forward, and no branch per lane); it writes back by the same
//! transpose, whole records with the inverse mass each lane read. From a slice of
//! `Vec3` it reads `x, y` with one 8-byte load and `z` with one 4-byte load. Both ways
//! give every lane the same bits, so the projection's results do not depend on which
//! runs.
//!
//! Every lane of a block is read, padding included: a padding lane names its block's first
//! tet's nodes ([`LaneBlock`]), which belong to this block alone within its colour, as a
//! tet that is not live keeps its own; lanes that are not live are then zeroed, as the
//! generic way leaves them. Only live lanes are written.

use glam::Vec3;

use super::lane_slots::LaneBlock;
use super::lanes::{LANES, Lane, LaneMath, V3};
use super::node_records::NodeRecord;
use super::shared_nodes::SharedNodes;

/// A lane type's way of reading and writing a block's nodes.
pub(crate) trait NodeLanes: Lane {
    /// Lane k is `v[idx[k]]` for k < `count`, zero past it (an index past `v` panics;
    /// the indices past `count` are read too, so they must name nodes of `v`).
    #[inline(always)]
    fn read_vec3s(v: &[Vec3], idx: &[u32; LANES], count: usize) -> V3<Self> {
        V3::gather(&std::array::from_fn(|k| {
            if k < count {
                v[idx[k] as usize]
            } else {
                Vec3::ZERO
            }
        }))
    }

    /// Lane k of `u[j]` and `w[j]`: node j of lane k's tet, displacement and inverse mass
    /// (zero where lane k is not live).
    ///
    /// # Safety
    /// No other thread may write these nodes during the call (colouring).
    #[inline(always)]
    unsafe fn load_nodes(b: &LaneBlock, nodes: &SharedNodes) -> ([V3<Self>; 4], [Self; 4]) {
        // Node j's x, y, z and w, lane by lane.
        let mut v = [[[0.0f32; LANES]; 4]; 4];
        for k in (0..LANES).filter(|&k| b.is_live(k)) {
            for (j, v) in v.iter_mut().enumerate() {
                // SAFETY: the caller's contract.
                let (u, w) = unsafe { nodes.get(b.nodes[j][k]) };
                [v[0][k], v[1][k], v[2][k], v[3][k]] = [u.x, u.y, u.z, w];
            }
        }
        // Written out, not `map`: an out-of-line `map` would be compiled without the
        // caller's AVX and call each intrinsic.
        (
            [row(&v[0]), row(&v[1]), row(&v[2]), row(&v[3])],
            [
                Self::new(v[0][3]),
                Self::new(v[1][3]),
                Self::new(v[2][3]),
                Self::new(v[3][3]),
            ],
        )
    }

    /// Write lane k of `u[j]` to node j of lane k's tet, for each live lane k; `w` is what
    /// [`NodeLanes::load_nodes`] read (a way that writes whole records writes it back).
    ///
    /// # Safety
    /// No other thread may read or write these nodes during the call (colouring).
    #[inline(always)]
    unsafe fn store_nodes(b: &LaneBlock, u: &[V3<Self>; 4], w: &[Self; 4], nodes: &SharedNodes) {
        let _ = w;
        // Each position stored once, then read lane by lane.
        let u = [
            u[0].to_arrays(),
            u[1].to_arrays(),
            u[2].to_arrays(),
            u[3].to_arrays(),
        ];
        for k in (0..LANES).filter(|&k| b.is_live(k)) {
            for (j, u) in u.iter().enumerate() {
                // SAFETY: the caller's contract.
                unsafe { nodes.set(b.nodes[j][k], Vec3::new(u[0][k], u[1][k], u[2][k])) };
            }
        }
    }
}

/// A node row's columns `x, y, z, w` as displacements and inverse masses, each zero where
/// `live` is clear (what the AVX and AVX-512 reads make of their transposed records).
#[inline(always)]
pub(super) fn masked_row<L: LaneMath>([x, y, z, w]: [L; 4], live: L) -> (V3<L>, L) {
    (
        V3 {
            x: x & live,
            y: y & live,
            z: z & live,
        },
        w & live,
    )
}

/// The displacements of a node row read lane by lane (x, y, z, w arrays).
#[inline(always)]
fn row<L: Lane>(v: &[[f32; LANES]; 4]) -> V3<L> {
    V3 {
        x: L::new(v[0]),
        y: L::new(v[1]),
        z: L::new(v[2]),
    }
}

impl NodeLanes for wide::f32x8 {}

#[cfg(target_arch = "x86_64")]
pub(super) use avx::rows_below;

#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;

    use super::super::lane_avx::Avx;
    use super::*;

    /// Lanes `[v[i0], …, v[i7]]` of `v` at the eight indices, each times `stride`, plus
    /// `offset`: eight 4-byte loads put together in registers. (No closure here or below
    /// calls an intrinsic: a closure is compiled without the caller's AVX and would call
    /// each one.)
    ///
    /// # Safety
    /// Every `stride × i + offset` is in bounds of `v`'s allocation; AVX2 is present.
    #[inline(always)]
    unsafe fn scalars(v: *const f32, idx: &[u32; LANES], stride: usize, offset: usize) -> __m256 {
        let at = |k: usize| stride * idx[k] as usize + offset;
        // SAFETY: the caller's contract.
        unsafe {
            let q0 = _mm_movelh_ps(
                _mm_unpacklo_ps(_mm_load_ss(v.add(at(0))), _mm_load_ss(v.add(at(1)))),
                _mm_unpacklo_ps(_mm_load_ss(v.add(at(2))), _mm_load_ss(v.add(at(3)))),
            );
            let q1 = _mm_movelh_ps(
                _mm_unpacklo_ps(_mm_load_ss(v.add(at(4))), _mm_load_ss(v.add(at(5)))),
                _mm_unpacklo_ps(_mm_load_ss(v.add(at(6))), _mm_load_ss(v.add(at(7)))),
            );
            _mm256_set_m128(q1, q0)
        }
    }

    /// `[x, y, 0, 0]` of the node at `p`, one 8-byte load.
    ///
    /// # Safety
    /// `p` and `p + 1` are in bounds; AVX2 is present.
    #[inline(always)]
    unsafe fn xy(p: *const f32) -> __m128i {
        // SAFETY: the caller's contract.
        unsafe { _mm_cvtsi64_si128((p as *const i64).read_unaligned()) }
    }

    /// `[x, y, x', y']` of the nodes at `p` and `q`.
    ///
    /// # Safety
    /// As [`xy`], for both.
    #[inline(always)]
    unsafe fn xy_pair(p: *const f32, q: *const f32) -> __m128 {
        // SAFETY: the caller's contract.
        unsafe { _mm_castsi128_ps(_mm_unpacklo_epi64(xy(p), xy(q))) }
    }

    /// The displacements of the nodes at the eight indices, lane by lane.
    ///
    /// # Safety
    /// Every index is a node of `base`'s array; AVX2 is present.
    #[inline(always)]
    unsafe fn positions(base: *const f32, idx: &[u32; LANES]) -> [__m256; 3] {
        // SAFETY: the caller's contract.
        unsafe {
            let at = |k: usize| base.add(3 * idx[k] as usize);
            // [x0 y0 x1 y1 | x4 y4 x5 y5] and [x2 y2 x3 y3 | x6 y6 x7 y7].
            let lo = _mm256_set_m128(xy_pair(at(4), at(5)), xy_pair(at(0), at(1)));
            let hi = _mm256_set_m128(xy_pair(at(6), at(7)), xy_pair(at(2), at(3)));
            [
                _mm256_shuffle_ps::<0x88>(lo, hi),
                _mm256_shuffle_ps::<0xDD>(lo, hi),
                scalars(base, idx, 3, 2),
            ]
        }
    }

    /// One node row of the block: the records of the eight lanes' nodes, transposed into
    /// displacements and inverse masses (lanes 0–3 in the low half, 4–7 in the high),
    /// zero where `live` is clear.
    ///
    /// # Safety
    /// Every index is a record of `base`'s array; AVX2 is present.
    #[inline(always)]
    unsafe fn read_node(base: *const NodeRecord, idx: &[u32; LANES], live: Avx) -> (V3<Avx>, Avx) {
        // SAFETY: the caller's contract.
        let [x, y, z, w] = unsafe {
            transpose(
                records(base, idx, 0),
                records(base, idx, 1),
                records(base, idx, 2),
                records(base, idx, 3),
            )
        };
        let raw = [
            Avx::from_raw(x),
            Avx::from_raw(y),
            Avx::from_raw(z),
            Avx::from_raw(w),
        ];
        masked_row(raw, live)
    }

    /// The records of lanes `k` (low half) and `k + 4` (high half).
    ///
    /// # Safety
    /// As [`read_node`].
    #[inline(always)]
    unsafe fn records(base: *const NodeRecord, idx: &[u32; LANES], k: usize) -> __m256 {
        // SAFETY: the caller's contract; a record is 16 bytes, 16-aligned.
        unsafe {
            let at = |k: usize| base.add(idx[k] as usize) as *const f32;
            let lo = _mm256_castps128_ps256(_mm_load_ps(at(k)));
            _mm256_insertf128_ps::<1>(lo, _mm_load_ps(at(k + 4)))
        }
    }

    /// Four rows of four values in each half, as four columns (and back: the transpose is
    /// its own inverse).
    #[inline(always)]
    fn transpose(r0: __m256, r1: __m256, r2: __m256, r3: __m256) -> [__m256; 4] {
        // SAFETY: AVX is present (every caller is compiled with it).
        unsafe {
            let t0 = _mm256_unpacklo_ps(r0, r1);
            let t1 = _mm256_unpackhi_ps(r0, r1);
            let t2 = _mm256_unpacklo_ps(r2, r3);
            let t3 = _mm256_unpackhi_ps(r2, r3);
            [
                _mm256_shuffle_ps::<0x44>(t0, t2),
                _mm256_shuffle_ps::<0xEE>(t0, t2),
                _mm256_shuffle_ps::<0x44>(t1, t3),
                _mm256_shuffle_ps::<0xEE>(t1, t3),
            ]
        }
    }

    /// Whether every index of the rows is below `len`.
    #[inline(always)]
    pub(in crate::xpbd) fn rows_below(rows: &[[u32; LANES]], len: usize) -> bool {
        if len == 0 || len > i32::MAX as usize {
            return len != 0 && rows.iter().flatten().all(|&i| (i as usize) < len);
        }
        // SAFETY: AVX2 is present (an `Avx` exists); a row is eight u32.
        unsafe {
            let last = _mm256_set1_epi32(len as i32 - 1);
            let mut top = _mm256_setzero_si256();
            for row in rows {
                top = _mm256_max_epu32(top, _mm256_loadu_si256(row.as_ptr() as *const __m256i));
            }
            _mm256_movemask_epi8(_mm256_cmpeq_epi32(_mm256_max_epu32(top, last), last)) == -1
        }
    }

    impl NodeLanes for Avx {
        #[inline(always)]
        fn read_vec3s(v: &[Vec3], idx: &[u32; LANES], count: usize) -> V3<Avx> {
            assert!(
                rows_below(std::slice::from_ref(idx), v.len()),
                "a node index past the mesh's {} nodes",
                v.len()
            );
            // SAFETY: every index is in bounds (checked); AVX2 is present.
            let [x, y, z] = unsafe { positions(v.as_ptr() as *const f32, idx) };
            let on = Avx::new(std::array::from_fn(|k| {
                f32::from_bits(if k < count { u32::MAX } else { 0 })
            }));
            V3 {
                x: Avx::from_raw(x) & on,
                y: Avx::from_raw(y) & on,
                z: Avx::from_raw(z) & on,
            }
        }

        #[inline(always)]
        unsafe fn load_nodes(b: &LaneBlock, nodes: &SharedNodes) -> ([V3<Avx>; 4], [Avx; 4]) {
            assert!(
                rows_below(&b.nodes, nodes.len()),
                "a lane block names a node past the mesh's"
            );
            let base = nodes.as_ptr() as *const NodeRecord;
            let live = Avx::new(b.live);
            // SAFETY: every index is in bounds (checked); AVX2 is present; the nodes are
            // this thread's (the caller's contract).
            unsafe {
                let r0 = read_node(base, &b.nodes[0], live);
                let r1 = read_node(base, &b.nodes[1], live);
                let r2 = read_node(base, &b.nodes[2], live);
                let r3 = read_node(base, &b.nodes[3], live);
                ([r0.0, r1.0, r2.0, r3.0], [r0.1, r1.1, r2.1, r3.1])
            }
        }

        #[inline(always)]
        unsafe fn store_nodes(b: &LaneBlock, u: &[V3<Avx>; 4], w: &[Avx; 4], nodes: &SharedNodes) {
            assert!(
                rows_below(&b.nodes, nodes.len()),
                "a lane block names a node past the mesh's"
            );
            let base = nodes.as_ptr() as *mut f32;
            // SAFETY: in bounds (checked); AVX2 is present; the nodes are this thread's.
            unsafe {
                let live = _mm256_movemask_ps(Avx::new(b.live).raw());
                for j in 0..4 {
                    let u = &u[j];
                    // Each live lane's record whole: its displacement and the inverse
                    // mass it was read with (a live lane's, unmasked).
                    let halves = transpose(u.x.raw(), u.y.raw(), u.z.raw(), w[j].raw());
                    let at = |k: usize| base.add(4 * b.nodes[j][k] as usize);
                    if live == 0xFF {
                        // Every lane live (the common block): no test per lane.
                        for (k, r) in halves.iter().enumerate() {
                            _mm_store_ps(at(k), _mm256_castps256_ps128(*r));
                            _mm_store_ps(at(k + 4), _mm256_extractf128_ps::<1>(*r));
                        }
                        continue;
                    }
                    for (k, r) in halves.iter().enumerate() {
                        if live & (1 << k) != 0 {
                            _mm_store_ps(at(k), _mm256_castps256_ps128(*r));
                        }
                        if live & (1 << (k + 4)) != 0 {
                            _mm_store_ps(at(k + 4), _mm256_extractf128_ps::<1>(*r));
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::xpbd::lane_slots::LaneSlots;
    use crate::xpbd::neo_hookean::TetTerms;
    use crate::xpbd::node_records::NodeRecord;
    use crate::xpbd::tet_slot::TetSlot;

    /// Nineteen tets on disjoint nodes (three blocks: one with a dead tet, one all live,
    /// the third with five padding lanes), tets 2 and 17 not live.
    fn blocks() -> LaneSlots {
        let slots: Vec<TetSlot> = (0..19u32)
            .map(|s| TetSlot {
                nodes: [4 * s, 4 * s + 1, 4 * s + 2, 4 * s + 3],
                terms: TetTerms {
                    dm_inv: glam::Mat3::IDENTITY,
                    alpha_h: 1.0,
                    alpha_d: 1.0,
                    gamma: 1.0,
                },
                live: s != 2 && s != 17,
            })
            .collect();
        LaneSlots::new(&slots, std::iter::once(0..19))
    }

    /// Node i's displacement and inverse mass, telling nodes apart.
    fn node(i: usize) -> (Vec3, f32) {
        let f = i as f32;
        (
            Vec3::new(f + 0.25, -2.0 * f, 0.5 * f - 7.0),
            1.0 / (1.0 + f),
        )
    }

    /// What a round trip read and left: the bits of every lane read (displacements, then
    /// inverse masses, block by block) and of the records after (displacement, then
    /// inverse mass).
    struct RoundTrip {
        read: Vec<u32>,
        nodes: Vec<[u32; 4]>,
    }

    /// Read every block, move each lane by its own offset, write it back.
    fn round_trip<L: NodeLanes>() -> RoundTrip {
        let slots = blocks();
        let mut records: Vec<NodeRecord> = (0..80)
            .map(|i| NodeRecord {
                u: node(i).0,
                w: node(i).1,
            })
            .collect();
        let shared = SharedNodes::new(&mut records);
        let mut read = Vec::new();
        for b in &slots.blocks {
            // SAFETY: one thread.
            let (u, m) = unsafe { L::load_nodes(b, &shared) };
            for u in &u {
                read.extend(u.to_arrays().iter().flatten().map(|f| f.to_bits()));
            }
            for m in &m {
                read.extend(m.to_array().map(f32::to_bits));
            }
            let step = L::new(std::array::from_fn(|k| 100.0 * (k + 1) as f32));
            let moved = u.map(|u| V3 {
                x: u.x + step,
                y: u.y - step,
                z: u.z * L::splat(2.0),
            });
            // SAFETY: one thread.
            unsafe { L::store_nodes(b, &moved, &m, &shared) };
        }
        let nodes = records
            .iter()
            .map(|r| r.u.extend(r.w).to_array().map(f32::to_bits))
            .collect();
        RoundTrip { read, nodes }
    }

    /// The AVX way reads the same bits into every lane as the generic one (zero where a
    /// lane is not live), and writes the live lanes' nodes alone: the dead tets' and the
    /// padding lanes' (which name the block's first tet's nodes) stay as they were, and
    /// every inverse mass is the one read (the AVX way writes whole records). Broken on
    /// purpose once (the AVX way writing the masked mass back): fails.
    #[test]
    fn avx_reads_and_writes_what_the_generic_way_does() {
        let generic = round_trip::<wide::f32x8>();
        for s in 0..19usize {
            for j in 0..4 {
                let i = 4 * s + j;
                let at_rest = node(i).0.extend(node(i).1).to_array().map(f32::to_bits);
                assert_eq!(generic.nodes[i][3], at_rest[3], "node {i}'s mass changed");
                if s == 2 || s == 17 {
                    assert_eq!(generic.nodes[i], at_rest, "dead tet {s} node {i} written");
                } else {
                    assert_ne!(
                        generic.nodes[i], at_rest,
                        "live tet {s} node {i} not written"
                    );
                }
            }
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let avx = round_trip::<super::super::lane_avx::Avx>();
            assert_eq!(avx.read, generic.read, "lanes read");
            assert_eq!(avx.nodes, generic.nodes, "nodes after the round trip");
        }
    }

    /// A slice read by indices (the implicit scheme's lanes): lane k is node `idx[k]` up
    /// to `count`, zero past it, the same bits either way; an index past the slice is
    /// refused by both.
    #[test]
    fn a_slice_reads_the_same_by_either_way() {
        let v: Vec<Vec3> = (0..48).map(|i| node(i).0).collect();
        let idx = [47, 3, 3, 0, 20, 1, 1, 1];
        let bits = |u: [[f32; LANES]; 3]| u.map(|c| c.map(f32::to_bits));
        let generic = bits(wide::f32x8::read_vec3s(&v, &idx, 5).to_arrays());
        for k in 0..LANES {
            let want = if k < 5 {
                v[idx[k] as usize]
            } else {
                Vec3::ZERO
            };
            assert_eq!(
                [0, 1, 2].map(|c| generic[c][k]),
                want.to_array().map(f32::to_bits)
            );
        }
        let past = [0, 1, 2, 48, 4, 5, 6, 7];
        let refused = |f: fn(&[Vec3], &[u32; LANES])| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(&v, &past))).is_err()
        };
        assert!(refused(|v, i| {
            wide::f32x8::read_vec3s(v, i, LANES);
        }));
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            use super::super::lane_avx::Avx;
            assert_eq!(bits(Avx::read_vec3s(&v, &idx, 5).to_arrays()), generic);
            assert!(refused(|v, i| {
                Avx::read_vec3s(v, i, LANES);
            }));
        }
    }
}
