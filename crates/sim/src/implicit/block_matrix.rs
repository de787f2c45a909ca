//! The Hessian `∇²G = M/h² + K(u)` of the free nodes assembled into 3×3 node blocks on
//! the mesh's node graph, whose pattern never changes (a released tet only stops adding
//! its blocks), and the symmetric block Gauss–Seidel sweep on it: the smoother of the
//! Newton step's preconditioner (docs/physics-notes.md, "The implicit scheme").

use glam::{Mat3, Vec3};

use super::block_lanes::{PAIRS, tet_blocks};
use super::coarse_assembly::pair_block;
use super::product_lanes::{RestLanes, TangentLanes};
use super::rest_tet::RestTet;
use super::tet_evals::TetEvals;
use crate::thread_team::{ThreadTeam, for_each_item};
use crate::xpbd::lanes::LANES;

/// A block-sparse symmetric matrix on the mesh's node graph, rows by node, columns
/// sorted, the diagonal included.
pub struct BlockMatrix {
    row_start: Vec<u32>,
    cols: Vec<u32>,
    blocks: Vec<Mat3>,
    /// Per tet, the slot of block (a, b) at `4a + b`, in row `node_a`.
    tet_slots: Vec<[u32; 16]>,
    /// The diagonal blocks inverted (the smoother's `D⁻¹`).
    d_inv: Vec<Mat3>,
    /// Partial sums of an assembly.
    parts: Vec<Vec<Mat3>>,
}

/// Partial sums of an assembly: a fixed count, so the sum does not depend on the thread
/// count.
const PARTS: usize = 2;

/// Part `k` of [`PARTS`] consecutive ranges covering `0..n`.
fn part(k: usize, n: usize) -> std::ops::Range<usize> {
    let per = n.div_ceil(PARTS).max(1);
    (k * per).min(n)..((k + 1) * per).min(n)
}

impl BlockMatrix {
    /// The pattern of `tets` over `node_count` nodes, all blocks zero.
    pub fn new(node_count: usize, tets: &[RestTet]) -> Self {
        let mut rows: Vec<Vec<u32>> = (0..node_count).map(|i| vec![i as u32]).collect();
        for t in tets {
            for &a in &t.nodes {
                rows[a as usize].extend_from_slice(&t.nodes);
            }
        }
        let mut row_start = vec![0u32];
        let mut cols = Vec::new();
        for r in &mut rows {
            r.sort_unstable();
            r.dedup();
            cols.extend_from_slice(r);
            row_start.push(cols.len() as u32);
        }
        let slot = |a: u32, b: u32| {
            let (s, e) = (
                row_start[a as usize] as usize,
                row_start[a as usize + 1] as usize,
            );
            (s + cols[s..e]
                .binary_search(&b)
                .expect("the pattern holds every tet pair")) as u32
        };
        let tet_slots = tets
            .iter()
            .map(|t| std::array::from_fn(|k| slot(t.nodes[k / 4], t.nodes[k % 4])))
            .collect();
        BlockMatrix {
            blocks: vec![Mat3::ZERO; cols.len()],
            d_inv: vec![Mat3::ZERO; node_count],
            parts: Vec::new(),
            row_start,
            cols,
            tet_slots,
        }
    }

    /// Assemble `M/h² + Σ_live K_t` at the evaluations' tangents and invert its
    /// diagonal blocks, `K_t` tet t's Hessian (PHYSICS.md §1.2's energy differentiated
    /// twice, `pair_block`), with `definite` its indefinite parts cut: `c ≥ 0` and
    /// `s₃ ≥ −μ/σ̂` (σ̂ ≥ 1 a Gershgorin bound of the largest stretch; at rest nothing is
    /// cut). Tets are summed in [`PARTS`] fixed ranges, shared by the members of `team`,
    /// then the parts in order: the result does not depend on the thread count.
    pub fn assemble(
        &mut self,
        (tets, b): (&[RestTet], &[[Vec3; 4]]),
        (evals, live): (&TetEvals, &[bool]),
        mass_over_h2: impl Fn(usize) -> f32,
        definite: bool,
        team: Option<&ThreadTeam>,
    ) {
        let mut parts = std::mem::take(&mut self.parts);
        parts.resize_with(PARTS, Vec::new);
        let sum_part = |k: usize, out: &mut Vec<Mat3>| {
            out.clear();
            out.resize(self.cols.len(), Mat3::ZERO);
            match evals {
                TetEvals::Lanes { rest, tangents, .. } => {
                    for c in part(k, rest.len()) {
                        self.add_chunk(out, c, (&rest[c], &tangents[c]), live, definite);
                    }
                }
                TetEvals::Scalar(_) => {
                    for t in part(k, tets.len()).filter(|&t| live[t]) {
                        self.add_tet(out, t, (tets[t].volume, &b[t]), evals, definite);
                    }
                }
            }
        };
        for_each_item(team, &mut parts, 1, sum_part);
        for (s, m) in self.blocks.iter_mut().enumerate() {
            *m = parts.iter().fold(Mat3::ZERO, |acc, p| acc + p[s]);
        }
        self.parts = parts;
        for i in 0..self.d_inv.len() {
            let d = self.diagonal_slot(i);
            self.blocks[d] += Mat3::IDENTITY * mass_over_h2(i);
            self.d_inv[i] = self.blocks[d].inverse();
        }
    }

    /// Add the blocks of chunk `c`'s live tets into `out` (ten computed in lanes, the other
    /// six their transposes).
    #[inline]
    fn add_chunk(
        &self,
        out: &mut [Mat3],
        c: usize,
        (rest, tan): (&RestLanes, &TangentLanes),
        live: &[bool],
        definite: bool,
    ) {
        let blocks = tet_blocks(rest, tan, definite);
        for k in (0..rest.count).filter(|&k| live[c * LANES + k]) {
            let slots = &self.tet_slots[c * LANES + k];
            for (e, &(a, b)) in blocks.iter().zip(PAIRS.iter()) {
                // Row-major entries: these are the transpose's columns.
                let m = Mat3::from_cols(
                    Vec3::new(e[0][k], e[1][k], e[2][k]),
                    Vec3::new(e[3][k], e[4][k], e[5][k]),
                    Vec3::new(e[6][k], e[7][k], e[8][k]),
                );
                out[slots[4 * a + b] as usize] += m.transpose();
                if a != b {
                    out[slots[4 * b + a] as usize] += m;
                }
            }
        }
    }

    /// Add tet `t`'s blocks into `out` (ten computed, the other six their transposes).
    #[inline]
    fn add_tet(
        &self,
        out: &mut [Mat3],
        t: usize,
        (volume, b): (f32, &[Vec3; 4]),
        evals: &TetEvals,
        definite: bool,
    ) {
        let tangent = evals.tangent(t);
        let tangent = if definite {
            tangent.definite()
        } else {
            tangent
        };
        let (f, cof, mu, c, s3) = tangent.parts();
        let scaled = (mu * volume, c * volume, s3 * volume);
        let g = b.map(|b| cof * b);
        let slots = &self.tet_slots[t];
        for a in 0..4 {
            for k in a..4 {
                let block = pair_block(b[a], b[k], (g[a], g[k]), &f, scaled);
                out[slots[4 * a + k] as usize] += block;
                if k != a {
                    out[slots[4 * k + a] as usize] += block.transpose();
                }
            }
        }
    }

    /// The slot of row `i`'s diagonal block.
    fn diagonal_slot(&self, i: usize) -> usize {
        let (s, e) = (self.row_start[i] as usize, self.row_start[i + 1] as usize);
        s + self.cols[s..e]
            .binary_search(&(i as u32))
            .expect("the diagonal is in the pattern")
    }

    /// Row `i`'s columns and blocks.
    fn row(&self, i: usize) -> (&[u32], &[Mat3]) {
        let (s, e) = (self.row_start[i] as usize, self.row_start[i + 1] as usize);
        (&self.cols[s..e], &self.blocks[s..e])
    }

    /// `out = A p` on the free nodes (zero at fixed ones, whose columns are skipped): what
    /// tests compare with the matrix-free product.
    #[cfg(test)]
    pub fn mul(&self, p: &[Vec3], out: &mut [Vec3], free: &[bool]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = Vec3::ZERO;
            if !free[i] {
                continue;
            }
            let (cols, blocks) = self.row(i);
            for (&j, m) in cols.iter().zip(blocks) {
                if free[j as usize] {
                    *o += *m * p[j as usize];
                }
            }
        }
    }

    /// `z = (D + U)⁻¹ D (D + L)⁻¹ r`: one symmetric block Gauss–Seidel sweep from zero
    /// (forward, then backward) on the free nodes (zero at fixed ones); symmetric positive
    /// definite, as the assembled matrix is.
    pub fn symmetric_gauss_seidel(&self, r: &[Vec3], z: &mut [Vec3], free: &[bool]) {
        let (n, d_inv) = (r.len(), &self.d_inv);
        for i in 0..n {
            if !free[i] {
                z[i] = Vec3::ZERO;
                continue;
            }
            let (cols, blocks) = self.row(i);
            let mut s = r[i];
            for (&j, m) in cols.iter().zip(blocks) {
                if (j as usize) < i && free[j as usize] {
                    s -= *m * z[j as usize];
                }
            }
            z[i] = d_inv[i] * s;
        }
        for i in (0..n).rev() {
            if !free[i] {
                continue;
            }
            let (cols, blocks) = self.row(i);
            let mut s = Vec3::ZERO;
            for (&j, m) in cols.iter().zip(blocks) {
                if (j as usize) > i && free[j as usize] {
                    s += *m * z[j as usize];
                }
            }
            z[i] -= d_inv[i] * s;
        }
    }
}
