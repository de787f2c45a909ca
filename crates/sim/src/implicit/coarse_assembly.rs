//! The coarse matrix `Pᵀ (M/h² + K(x)) P` re-assembled from the tets' current tangents
//! (docs/physics-notes.md, "The implicit scheme": the coarse refresh).
//!
//! A tet's nodes interpolate from a few coarse corners `j` (their union, usually 8–16).
//! With `w_aj` node a's weight on corner j, a coarse displacement `X_j` moves the tet by
//! `dF = Σ_j X_j β_jᵀ`, `β_j = Σ_a w_aj b_a` (the corner's *coarse shape gradient* in this
//! tet, fixed at rest). The tet's Galerkin block between corners j and k is then the
//! fine block of [`super::TetTangent`] with `b` replaced by `β`:
//!
//! ```text
//! A_jk = V [ μ (β_j·β_k) I + c (cof F β_j)(cof F β_k)ᵀ − s₃ [F (β_j × β_k)]ₓ ]
//! ```
//!
//! (`[g]ₓ v = g × v`; the last term is `e_rᵀ dcof[e_s β_kᵀ] β_j`, PHYSICS.md §1.2's energy
//! differentiated twice). `c` is clamped at zero as in the block Jacobi part, so the
//! matrix stays positive definite where the tangent is only a little indefinite; where it
//! is not, the factorisation fails and the caller keeps the previous factor. The pairs
//! `(j, k)` of every tet and the coarse block each adds to are found once: a refresh is
//! arithmetic and sums, and a released tet only drops out of the sum.

use rustc_hash::FxHashMap as HashMap;
use std::ops::Range;

use glam::{Mat3, Vec3};

use super::block_lanes::pair_entries;
use super::coarse_grid::CoarseGrid;
use super::rest_tet::RestTet;
use super::tet_tangent::TetTangent;
use crate::thread_team::{ThreadTeam, for_each_item};
use crate::xpbd::lanes::{LANES, Lane, M3, V3, store_vec};

/// Partial sums of a refresh: a fixed count, so the result does not depend on the
/// thread count (each part sums its groups in order, the parts are added in order).
const PARTS: usize = 4;

/// Fewest coarse blocks in a part of the pass that adds the partial sums.
const SUM_BLOCKS: usize = 512;

/// Most coarse corners one tet's four nodes interpolate from (8 each).
const MAX_CORNERS: usize = 32;

/// Tets with the same coarse corners (the same corner pairs, so the same coarse blocks):
/// summed eight at a time in SIMD lanes, then added to the coarse blocks once.
#[derive(Debug, Clone)]
struct Group {
    /// Its pairs' coarse blocks in [`CoarseAssembly::pair_slots`].
    slots: Range<usize>,
    /// Its chunks of eight tets in [`CoarseAssembly::chunks`].
    chunks: Range<usize>,
}

/// Up to eight tets of one group, with their `β_j` stored lane by lane.
#[derive(Debug, Clone)]
struct Chunk {
    /// Mesh indices (the first `count` are used).
    tets: [u32; LANES],
    count: usize,
    /// `β_j` of each corner in [`CoarseAssembly::beta_lanes`].
    beta: Range<usize>,
}

/// Per tet, its coarse corners' shape gradients, grouped by corner set, and the coarse
/// blocks of their corner pairs.
#[derive(Debug, Clone)]
pub struct CoarseAssembly {
    /// Per tet, its group (`u32::MAX`: no free corner) and the range of `beta` holding
    /// its `β_j` (corners by descending coarse id).
    tet_group: Vec<u32>,
    corner_offsets: Vec<u32>,
    beta: Vec<Vec3>,
    /// Rest volume per tet.
    volume: Vec<f32>,
    groups: Vec<Group>,
    /// Per group, the coarse block of each pair `j ≤ k`, row-major over the pairs.
    pair_slots: Vec<u32>,
    chunks: Vec<Chunk>,
    beta_lanes: Vec<[[f32; LANES]; 3]>,
    /// The groups each partial sum covers (about equal work).
    part_groups: Vec<Range<usize>>,
    /// Coarse blocks in all.
    blocks: usize,
    /// The partial sums of the last refresh, kept to avoid allocating per refresh.
    parts: Vec<Vec<[f64; 9]>>,
}

/// The tets of a mesh grouped by their coarse corners on a grid: per tet its corners'
/// `β_j`, and the distinct corner sets with their tets — what both the coarse matrix's
/// pattern and its assembly are built from, found once.
#[derive(Debug, Clone)]
pub struct Grouping {
    tet_group: Vec<u32>,
    corner_offsets: Vec<u32>,
    beta: Vec<Vec3>,
    /// Per group, its corners (descending coarse id) and its tets.
    members: Vec<(Vec<u32>, Vec<u32>)>,
}

impl Grouping {
    /// The corners (those with a nonzero weight at one of its nodes) of every tet of
    /// `tets` (shape gradients `b`) on `grid`, grouped by corner set.
    pub fn new(grid: &CoarseGrid, tets: &[RestTet], b: &[[Vec3; 4]]) -> Self {
        let mut corner_offsets = vec![0u32];
        let mut beta = Vec::new();
        let mut tet_group = Vec::with_capacity(tets.len());
        let mut by_corners: HashMap<Vec<u32>, usize> = HashMap::default();
        let mut members: Vec<(Vec<u32>, Vec<u32>)> = Vec::new();
        let mut ids: Vec<u32> = Vec::with_capacity(MAX_CORNERS);
        for (t, (tet, b)) in tets.iter().zip(b).enumerate() {
            let corners = tet_corners(grid, tet, b);
            beta.extend(corners.iter().map(|c| c.1));
            corner_offsets.push(beta.len() as u32);
            if corners.is_empty() {
                tet_group.push(u32::MAX);
                continue;
            }
            ids.clear();
            ids.extend(corners.iter().map(|c| c.0));
            let g = *by_corners.entry(ids.clone()).or_insert_with(|| {
                members.push((ids.clone(), Vec::new()));
                members.len() - 1
            });
            members[g].1.push(t as u32);
            tet_group.push(g as u32);
        }
        Grouping {
            tet_group,
            corner_offsets,
            beta,
            members,
        }
    }

    /// The distinct corner sets, each in descending coarse id.
    pub fn corner_sets(&self) -> impl Iterator<Item = &[u32]> {
        self.members.iter().map(|(ids, _)| ids.as_slice())
    }
}

impl CoarseAssembly {
    /// The pairs of every group of `grouping` (the tets of `tets`, by their corners);
    /// `index` maps a lower-triangle coarse block `(row, col)` to its index (it holds every
    /// pair of one group's corners, as [`super::CoarseSystem::with_assembly`] builds it
    /// from [`Grouping::corner_sets`]).
    pub fn new(grouping: Grouping, tets: &[RestTet], index: &HashMap<(u32, u32), usize>) -> Self {
        let Grouping {
            tet_group,
            corner_offsets,
            beta,
            members,
        } = grouping;
        let mut this = CoarseAssembly {
            tet_group,
            corner_offsets,
            beta,
            volume: tets.iter().map(|t| t.volume).collect(),
            groups: Vec::with_capacity(members.len()),
            pair_slots: Vec::new(),
            chunks: Vec::new(),
            beta_lanes: Vec::new(),
            part_groups: Vec::new(),
            blocks: index.len(),
            parts: vec![vec![[0.0; 9]; index.len()]; PARTS],
        };
        for (ids, tets) in &members {
            this.push_group(ids, tets, index);
        }
        this.part_groups = balanced_parts(&this.groups);
        this
    }

    /// Append the group of `tets` with corners `ids`: its pair slots and its chunks.
    fn push_group(&mut self, ids: &[u32], tets: &[u32], index: &HashMap<(u32, u32), usize>) {
        let slots = self.pair_slots.len();
        for (j, &v) in ids.iter().enumerate() {
            for &w in &ids[j..] {
                self.pair_slots.push(index[&(v, w)] as u32);
            }
        }
        let chunks = self.chunks.len();
        for chunk in tets.chunks(LANES) {
            let start = self.beta_lanes.len();
            self.beta_lanes.resize(start + ids.len(), [[0.0; LANES]; 3]);
            let mut c = Chunk {
                tets: [0; LANES],
                count: chunk.len(),
                beta: start..start + ids.len(),
            };
            for (k, &t) in chunk.iter().enumerate() {
                c.tets[k] = t;
                let range = self.corner_offsets[t as usize] as usize
                    ..self.corner_offsets[t as usize + 1] as usize;
                for (j, bj) in self.beta[range].iter().enumerate() {
                    store_vec(&mut self.beta_lanes[start + j], k, *bj);
                }
            }
            self.chunks.push(c);
        }
        self.groups.push(Group {
            slots: slots..self.pair_slots.len(),
            chunks: chunks..self.chunks.len(),
        });
    }

    /// Tet `t`'s `β_j`.
    fn tet_beta(&self, t: usize) -> &[Vec3] {
        &self.beta[self.corner_offsets[t] as usize..self.corner_offsets[t + 1] as usize]
    }

    /// `out = base + Σ` over the tets with a tangent (`tangent(t)` is `None` for a
    /// released tet) of their Galerkin blocks, row-major per block; eight tets of a group
    /// at a time in SIMD lanes (AVX2 where the CPU has it), the [`PARTS`] partial sums and
    /// then the blocks shared by the members of `team` (this thread alone without one).
    pub fn assemble<'a>(
        &mut self,
        base: &[[f64; 9]],
        tangent: impl Fn(usize) -> Option<&'a TetTangent> + Sync,
        out: &mut [[f64; 9]],
        team: Option<&ThreadTeam>,
    ) {
        let mut parts = std::mem::take(&mut self.parts);
        let this = &*self;
        for_each_item(team, &mut parts, 1, |k, sums| {
            sums.iter_mut().for_each(|s| *s = [0.0; 9]);
            let mut acc = Vec::new();
            for g in &this.groups[this.part_groups[k].clone()] {
                this.add_group(g, &tangent, &mut acc, sums);
            }
        });
        let sums = &parts;
        for_each_item(team, &mut out[..self.blocks], SUM_BLOCKS, |i, o| {
            let mut s = base[i];
            for p in sums {
                for (s, v) in s.iter_mut().zip(&p[i]) {
                    *s += v;
                }
            }
            *o = s;
        });
        self.parts = parts;
    }

    /// Add `scale` times tet `t`'s Galerkin blocks at `tan` to `sums`, one pair at a time
    /// (a released tet's, taken out again; the reference for the lanes).
    pub fn add_tet(&self, t: usize, tan: &TetTangent, scale: f64, sums: &mut [[f64; 9]]) {
        let Some(g) = self.groups.get(self.tet_group[t] as usize) else {
            return;
        };
        let beta = self.tet_beta(t);
        let mut slots = self.pair_slots[g.slots.clone()].iter();
        let (f, cof, mu, c, s3) = tan.parts();
        let v = self.volume[t];
        let (mu, c, s3) = (mu * v, c.max(0.0) * v, s3 * v);
        let a: Vec<Vec3> = beta.iter().map(|b| cof * *b).collect();
        for (j, bj) in beta.iter().enumerate() {
            for (k, bk) in beta.iter().enumerate().skip(j) {
                let block = pair_block(*bj, *bk, (a[j], a[k]), &f, (mu, c, s3));
                let slot = *slots.next().expect("a slot per pair") as usize;
                add_row_major(&mut sums[slot], &block, scale);
            }
        }
    }

    /// Add group `g`'s blocks to `sums` (`acc`: the lanes' running sums per pair).
    fn add_group<'a>(
        &self,
        g: &Group,
        tangent: &impl Fn(usize) -> Option<&'a TetTangent>,
        acc: &mut Vec<[[f32; LANES]; 9]>,
        sums: &mut [[f64; 9]],
    ) {
        acc.clear();
        acc.resize(g.slots.len(), [[0.0; LANES]; 9]);
        for chunk in &self.chunks[g.chunks.clone()] {
            let lanes = self.chunk_tangents(chunk, tangent);
            let beta = &self.beta_lanes[chunk.beta.clone()];
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2.
                unsafe { chunk_pairs_avx2(&lanes, beta, acc) };
                continue;
            }
            chunk_pairs::<wide::f32x8>(&lanes, beta, acc);
        }
        for (slot, a) in self.pair_slots[g.slots.clone()].iter().zip(acc.iter()) {
            let sum = &mut sums[*slot as usize];
            for (s, lanes) in sum.iter_mut().zip(a) {
                *s += lanes.iter().map(|&x| x as f64).sum::<f64>();
            }
        }
    }

    /// The chunk's tangents in lanes, `(μ, c⁺, s₃)` times the volume (zero for a
    /// released tet and the padding).
    fn chunk_tangents<'a>(
        &self,
        chunk: &Chunk,
        tangent: &impl Fn(usize) -> Option<&'a TetTangent>,
    ) -> ChunkTangents {
        let mut out = ChunkTangents {
            f: [Mat3::IDENTITY; LANES],
            cof: [Mat3::IDENTITY; LANES],
            scalars: [[0.0; LANES]; 3],
        };
        for k in 0..chunk.count {
            let t = chunk.tets[k] as usize;
            if let Some(tan) = tangent(t) {
                let (f, cof, mu, c, s3) = tan.parts();
                let v = self.volume[t];
                (out.f[k], out.cof[k]) = (f, cof);
                out.scalars[0][k] = mu * v;
                out.scalars[1][k] = c.max(0.0) * v;
                out.scalars[2][k] = s3 * v;
            }
        }
        out
    }
}

/// Eight tets' `F`, `cof F` and `(μ V, c⁺ V, s₃ V)`.
struct ChunkTangents {
    f: [Mat3; LANES],
    cof: [Mat3; LANES],
    scalars: [[f32; LANES]; 3],
}

/// [`chunk_pairs`] with AVX lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn chunk_pairs_avx2(
    tan: &ChunkTangents,
    beta: &[[[f32; LANES]; 3]],
    acc: &mut [[[f32; LANES]; 9]],
) {
    chunk_pairs::<crate::xpbd::lane_avx::Avx>(tan, beta, acc);
}

/// Add the blocks of every pair `j ≤ k` of eight tets (lanes) to `acc`, row-major:
/// [`pair_block`] written out per entry.
#[inline(always)]
fn chunk_pairs<L: Lane>(
    tan: &ChunkTangents,
    beta: &[[[f32; LANES]; 3]],
    acc: &mut [[[f32; LANES]; 9]],
) {
    let (f, cof) = (M3::<L>::gather(&tan.f), M3::<L>::gather(&tan.cof));
    let (mu, c, s3) = (
        L::new(tan.scalars[0]),
        L::new(tan.scalars[1]),
        L::new(tan.scalars[2]),
    );
    let m = beta.len().min(MAX_CORNERS);
    let mut b = [V3::<L>::ZERO; MAX_CORNERS];
    let mut a = [V3::<L>::ZERO; MAX_CORNERS];
    for j in 0..m {
        b[j] = V3::load(&beta[j]);
        a[j] = cof.mul_vec(b[j]);
    }
    let mut pairs = acc.iter_mut();
    for j in 0..m {
        let ca = a[j] * c;
        for k in j..m {
            let d = b[j].dot(b[k]) * mu;
            let g = f.mul_vec(b[j].cross(b[k])) * s3;
            let sum = pairs.next().expect("a sum per pair");
            for (s, e) in sum.iter_mut().zip(pair_entries(d, ca, a[k], g)) {
                *s = (L::new(*s) + e).to_array();
            }
        }
    }
}

/// Split `groups` into [`PARTS`] consecutive ranges of about equal work (pairs × tets).
fn balanced_parts(groups: &[Group]) -> Vec<Range<usize>> {
    let work = |g: &Group| g.slots.len() * g.chunks.len();
    let total: usize = groups.iter().map(work).sum();
    let mut bounds = vec![0];
    let mut done = 0;
    for (i, g) in groups.iter().enumerate() {
        done += work(g);
        if bounds.len() < PARTS && done * PARTS >= total * bounds.len() {
            bounds.push(i + 1);
        }
    }
    while bounds.len() <= PARTS {
        bounds.push(groups.len());
    }
    bounds.windows(2).map(|w| w[0]..w[1]).collect()
}

/// `V A_jk` with the volume folded into `(μ, c, s₃)`: `μ (β_j·β_k) I + c a_j a_kᵀ −
/// s₃ [F (β_j × β_k)]ₓ`, `a = cof F β` (module docs; PHYSICS.md §1.2).
#[inline]
pub(super) fn pair_block(
    bj: Vec3,
    bk: Vec3,
    (aj, ak): (Vec3, Vec3),
    f: &Mat3,
    (mu, c, s3): (f32, f32, f32),
) -> Mat3 {
    let g = (*f * bj.cross(bk)) * s3;
    let skew = Mat3::from_cols(
        Vec3::new(0.0, g.z, -g.y),
        Vec3::new(-g.z, 0.0, g.x),
        Vec3::new(g.y, -g.x, 0.0),
    );
    let ca = aj * c;
    Mat3::IDENTITY * (mu * bj.dot(bk)) + Mat3::from_cols(ca * ak.x, ca * ak.y, ca * ak.z) - skew
}

/// `sum += scale · m`, `sum` row-major.
#[inline]
fn add_row_major(sum: &mut [f64; 9], m: &Mat3, scale: f64) {
    for c in 0..3 {
        let col = m.col(c);
        sum[c] += scale * col.x as f64;
        sum[3 + c] += scale * col.y as f64;
        sum[6 + c] += scale * col.z as f64;
    }
}

/// A tet's coarse corners with a nonzero weight, by descending id (so a pair `j ≤ k` is a
/// lower-triangle block `(v_j, v_k)`), each with its `β_j = Σ_a w_aj b_a`.
fn tet_corners(grid: &CoarseGrid, t: &RestTet, b: &[Vec3; 4]) -> Vec<(u32, Vec3)> {
    let mut corners: Vec<(u32, Vec3)> = Vec::with_capacity(MAX_CORNERS);
    for (a, &node) in t.nodes.iter().enumerate() {
        for &(id, w) in grid.weights[node as usize]
            .iter()
            .filter(|(_, w)| *w != 0.0)
        {
            match corners.iter_mut().find(|(c, _)| *c == id) {
                Some(c) => c.1 += b[a] * w,
                None => corners.push((id, b[a] * w)),
            }
        }
    }
    corners.sort_unstable_by_key(|c| std::cmp::Reverse(c.0));
    corners
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::implicit::CoarseSystem;
    use crate::material::Lame;
    use crate::vbd::shape_gradients;

    /// The refreshed blocks against `Pᵀ K(x) P` formed densely from the tangent's own
    /// product `dP[dF]`, at a stretched, sheared and rotated state with some tets released.
    #[test]
    fn the_refresh_is_the_galerkin_product_of_the_current_tangent() {
        let (mesh, grid, tets) = crate::implicit::coarse_grid::test_block();
        let lame = Lame {
            mu: 6.2e4,
            lambda: 5.59e5,
        };
        // The pattern's factor needs a mass; the blocks compared below leave it out.
        let mass = mesh.lumped_masses(1040.0);
        let b: Vec<[Vec3; 4]> = tets.iter().map(|t| shape_gradients(&t.dm_inv)).collect();
        let (sys, mut asm) =
            CoarseSystem::with_assembly(&grid, (&tets, &b), (&mass, 3600.0)).unwrap();
        // Displacements: a quarter turn's worth of rotation about z plus a stretch in x
        // and a wobble, so F is far from I and the tangent far from its rest value.
        let rot = Mat3::from_rotation_z(0.6);
        let u: Vec<Vec3> = mesh
            .rest_positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let s = Vec3::new(1.4 * p.x, 0.9 * p.y, p.z + 0.2 * p.x);
                rot * s - *p + Vec3::splat(1e-3 * (i as f32 * 0.7).sin())
            })
            .collect();
        let tangents: Vec<TetTangent> = tets
            .iter()
            .map(|t| TetTangent::at(&t.strain(&u), lame))
            .collect();
        let live: Vec<bool> = (0..tets.len()).map(|t| t % 7 != 2).collect();
        let mut out = vec![[0.0; 9]; sys.block_index().len()];
        let zero = vec![[0.0; 9]; out.len()];
        let team = ThreadTeam::new(3).unwrap();
        asm.assemble(
            &zero,
            |t| live[t].then(|| &tangents[t]),
            &mut out,
            Some(&team),
        );
        let mut serial = vec![[1.0; 9]; out.len()];
        asm.assemble(&zero, |t| live[t].then(|| &tangents[t]), &mut serial, None);
        assert_eq!(out, serial, "the same sums on any thread count");
        let nc = 3 * grid.count;
        let mut dense = vec![0.0f64; nc * nc];
        for (t, tet) in tets.iter().enumerate().filter(|(t, _)| live[*t]) {
            for a in 0..4 {
                for c in 0..4 {
                    // K[a][c]_{rs} = e_rᵀ V dP[e_s b_cᵀ] b_a.
                    let cols: [Vec3; 3] = std::array::from_fn(|s| {
                        let mut e = Vec3::ZERO;
                        e[s] = 1.0;
                        let df = Mat3::from_cols(e * b[t][c].x, e * b[t][c].y, e * b[t][c].z);
                        tangents[t].dp(&df) * b[t][a] * tet.volume
                    });
                    for &(v, wa) in &grid.weights[tet.nodes[a] as usize] {
                        for &(w, wc) in &grid.weights[tet.nodes[c] as usize] {
                            for r in 0..3 {
                                for s in 0..3 {
                                    dense[(3 * v as usize + r) * nc + 3 * w as usize + s] +=
                                        (wa * wc * cols[s][r]) as f64;
                                }
                            }
                        }
                    }
                }
            }
        }
        let scale = dense.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut worst = 0.0f64;
        for (&(v, w), &k) in sys.block_index() {
            for r in 0..3 {
                for s in 0..3 {
                    let want = dense[(3 * v as usize + r) * nc + 3 * w as usize + s];
                    worst = worst.max((out[k][3 * r + s] - want).abs());
                }
            }
        }
        assert!(
            scale > 0.0 && worst < 1e-4 * scale,
            "off by {worst} of {scale}"
        );
    }
}
