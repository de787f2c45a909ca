//! The coarse level's matrix `A_c = Pᵀ A P` (Galerkin) and its sparse Cholesky factor.
//!
//! `A` is `M/h² + K`, with `K` first the small-strain (rest) stiffness of the tets, so the
//! pattern is fixed from the start: a released tet only subtracts its own contribution
//! and the factor is refreshed numerically on the same symbolic analysis
//! (`../shared/SOLVERS.md`, "a cut that only releases tets never changes the sparsity
//! pattern"). [`CoarseSystem::refresh`] re-assembles `K` from the live tets' current
//! tangents on the same pattern ([`CoarseAssembly`]), so the coarse level follows the
//! rotations and large strains the rest stiffness gets wrong; the fine level corrects the
//! rest either way: this is only the preconditioner's coarse part.

use rustc_hash::FxHashMap as HashMap;

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{MatMut, Side};
use glam::{Mat3, Vec3};

use super::coarse_assembly::{CoarseAssembly, Grouping};
use super::coarse_grid::CoarseGrid;
use super::rest_tet::RestTet;
use super::tet_tangent::TetTangent;
use crate::thread_team::ThreadTeam;

/// Why the coarse factorisation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the coarse level of the implicit solver could not be factorised: {0}")]
pub struct CoarseError(String);

impl CoarseError {
    /// An error saying `why`.
    pub(crate) fn new(why: &str) -> Self {
        CoarseError(why.to_string())
    }
}

/// Block `(row, col)` with row ≥ col → its index among the blocks.
type BlockIndex = HashMap<(u32, u32), usize>;

/// `A_c` in 3×3 blocks (lower triangle) and its factor.
pub struct CoarseSystem {
    /// Block `(row, col)` with row ≥ col → its index in `blocks`.
    index: HashMap<(u32, u32), usize>,
    /// Row-major 3×3 values of each block.
    blocks: Vec<[f64; 9]>,
    /// The mass part `Pᵀ (M/h²) P` of each block (what a refresh adds the tets to).
    mass_blocks: Vec<[f64; 9]>,
    /// Per block, the position of each of its nine values in the CSC values (`u32::MAX`
    /// above the diagonal of a diagonal block).
    position: Vec<[u32; 9]>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    symbolic: SymbolicLlt<usize>,
    factor: Llt<usize, f64>,
}

impl CoarseSystem {
    /// `Pᵀ (M/h² + K_rest) P` over `tets` (shape gradients `b`, every one live) and the
    /// nodes' `mass`, factorised, with the assembly that refreshes it: the pattern of
    /// [`CoarseSystem::with_assembly`] filled as a refresh at the tangent `rest` (at rest,
    /// linear elasticity), so the tets are summed by corner group in SIMD lanes, not pair
    /// by pair.
    pub fn at_rest(
        grid: &CoarseGrid,
        tets: (&[RestTet], &[[Vec3; 4]]),
        mass: (&[f32], f32),
        rest: &TetTangent,
        team: Option<&ThreadTeam>,
    ) -> Result<(Self, CoarseAssembly), CoarseError> {
        let (mut system, mut assembly) = Self::with_assembly(grid, tets, mass)?;
        system.refresh(&mut assembly, |_| Some(rest), team)?;
        Ok((system, assembly))
    }

    /// `Pᵀ (M/h²) P` on the pattern of `tets`' corner pairs (shape gradients `b`, lumped
    /// `mass`), factorised, with the assembly a refresh fills it by: the tets are grouped
    /// by corner set once, for both (`Grouping`).
    pub fn with_assembly(
        grid: &CoarseGrid,
        (tets, b): (&[RestTet], &[[Vec3; 4]]),
        (mass, inv_h2): (&[f32], f32),
    ) -> Result<(Self, CoarseAssembly), CoarseError> {
        let grouping = Grouping::new(grid, tets, b);
        let system = Self::mass_only(grid, grouping.corner_sets(), mass, inv_h2)?;
        let assembly = CoarseAssembly::new(grouping, tets, &system.index);
        Ok((system, assembly))
    }

    /// `Pᵀ (M/h²) P` on the pattern of every pair of coarse nodes within one of the
    /// `corner_sets` (each the coarse nodes one tet interpolates from), factorised: what
    /// a refresh then fills with the tangents.
    fn mass_only<'a>(
        grid: &CoarseGrid,
        corner_sets: impl IntoIterator<Item = &'a [u32]>,
        mass: &[f32],
        inv_h2: f32,
    ) -> Result<Self, CoarseError> {
        let mut index = HashMap::default();
        let mut blocks = Vec::new();
        for ids in corner_sets {
            for (j, &v) in ids.iter().enumerate() {
                for &w in &ids[j..] {
                    add_block(&mut index, &mut blocks, (v.max(w), v.min(w)), &Mat3::ZERO);
                }
            }
        }
        Self::with_mass(grid, (index, blocks), mass, inv_h2)
    }

    /// The blocks `(index, blocks)` plus the mass part, on their pattern, factorised.
    fn with_mass(
        grid: &CoarseGrid,
        (mut index, mut blocks): (BlockIndex, Vec<[f64; 9]>),
        mass: &[f32],
        inv_h2: f32,
    ) -> Result<Self, CoarseError> {
        let mut mass_blocks = vec![[0.0; 9]; blocks.len()];
        for (i, w) in grid.weights.iter().enumerate() {
            node_mass(w, mass[i] * inv_h2, &mut |v, u, b| {
                let k = add_block(&mut index, &mut blocks, (v, u), &b);
                mass_blocks.resize(blocks.len(), [0.0; 9]);
                accumulate(&mut mass_blocks[k], &b, 1.0);
            });
        }
        let n = 3 * grid.count;
        let (col_ptr, row_idx, position) = pattern(&index, grid.count);
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic =
            SymbolicLlt::try_new(sym, Side::Lower).map_err(|e| CoarseError(format!("{e:?}")))?;
        let values = block_values(&blocks, &position, row_idx.len());
        let factor = factorise(&symbolic, &col_ptr, &row_idx, &values)?;
        Ok(CoarseSystem {
            index,
            blocks,
            mass_blocks,
            position,
            col_ptr,
            row_idx,
            values,
            symbolic,
            factor,
        })
    }

    /// Re-assemble the matrix from the mass and the tets' current tangents (`tangent(t)`
    /// `None` for a released tet) and refactorise on the same pattern; when the new matrix
    /// is not positive definite the previous factor stays and the error says so.
    pub fn refresh<'a>(
        &mut self,
        assembly: &mut CoarseAssembly,
        tangent: impl Fn(usize) -> Option<&'a TetTangent> + Sync,
        team: Option<&ThreadTeam>,
    ) -> Result<(), CoarseError> {
        assembly.assemble(&self.mass_blocks, tangent, &mut self.blocks, team);
        self.refactor()
    }

    /// Subtract released tets' blocks at the tangents `used` (per tet, those of the last
    /// [`CoarseSystem::refresh`]); the factor is the old one until [`CoarseSystem::refactor`].
    pub fn subtract(&mut self, assembly: &CoarseAssembly, tets: &[u32], used: &[TetTangent]) {
        for &t in tets {
            assembly.add_tet(t as usize, &used[t as usize], -1.0, &mut self.blocks);
        }
    }

    /// Lower-triangle coarse block `(row, col)` → its index (what `CoarseAssembly` reads).
    pub fn block_index(&self) -> &HashMap<(u32, u32), usize> {
        &self.index
    }

    /// Solve `A_c x = b` in place (3 values per coarse node).
    pub fn solve(&self, b: &mut [f64]) {
        let n = b.len();
        self.factor
            .solve_in_place(MatMut::from_column_major_slice_mut(b, n, 1));
    }

    /// `A_c⁻¹` as a dense matrix (3 rows per coarse node; symmetric, so row- and
    /// column-major alike), from the factor: what the GPU applies as a mat-vec.
    pub(crate) fn dense_inverse(&self) -> Vec<f64> {
        let n = self.col_ptr.len() - 1;
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            m[i * n + i] = 1.0;
        }
        self.factor
            .solve_in_place(MatMut::from_column_major_slice_mut(&mut m, n, n));
        m
    }

    /// Nonzeros of the lower triangle of `A_c`.
    pub fn nonzeros(&self) -> usize {
        self.row_idx.len()
    }

    /// Copy the blocks into the CSC values and factorise numerically (the previous factor
    /// stays when this fails).
    pub fn refactor(&mut self) -> Result<(), CoarseError> {
        fill_block_values(&self.blocks, &self.position, &mut self.values);
        self.factor = factorise(&self.symbolic, &self.col_ptr, &self.row_idx, &self.values)?;
        Ok(())
    }
}

/// The CSC values of `blocks` placed at `position`.
fn block_values(blocks: &[[f64; 9]], position: &[[u32; 9]], len: usize) -> Vec<f64> {
    let mut values = vec![0.0; len];
    fill_block_values(blocks, position, &mut values);
    values
}

/// Write `blocks` into the CSC `values` at `position`.
fn fill_block_values(blocks: &[[f64; 9]], position: &[[u32; 9]], values: &mut [f64]) {
    for (b, pos) in blocks.iter().zip(position) {
        for k in 0..9 {
            if pos[k] != u32::MAX {
                values[pos[k] as usize] = b[k];
            }
        }
    }
}

/// The numeric LLᵀ factor of the lower-triangle CSC matrix on `symbolic`'s analysis.
fn factorise(
    symbolic: &SymbolicLlt<usize>,
    col_ptr: &[usize],
    row_idx: &[usize],
    values: &[f64],
) -> Result<Llt<usize, f64>, CoarseError> {
    let n = col_ptr.len() - 1;
    let sym = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
    Llt::try_new_with_symbolic(
        symbolic.clone(),
        SparseColMatRef::new(sym, values),
        Side::Lower,
    )
    .map_err(|e| CoarseError(format!("{e:?}")))
}

/// Add `m` to block `(v, w)`, numbering it if it is new; returns its number.
fn add_block(
    index: &mut HashMap<(u32, u32), usize>,
    blocks: &mut Vec<[f64; 9]>,
    vw: (u32, u32),
    m: &Mat3,
) -> usize {
    let k = *index.entry(vw).or_insert_with(|| {
        blocks.push([0.0; 9]);
        blocks.len() - 1
    });
    accumulate(&mut blocks[k], m, 1.0);
    k
}

/// `b += scale · m` in row-major order.
fn accumulate(b: &mut [f64; 9], m: &Mat3, scale: f64) {
    for r in 0..3 {
        for c in 0..3 {
            b[3 * r + c] += scale * m.col(c)[r] as f64;
        }
    }
}

/// Call `out(v, w, block)` for a node's mass term `Pᵀ (m/h² I) P` (lower triangle).
fn node_mass(weights: &[(u32, f32); 8], m: f32, out: &mut impl FnMut(u32, u32, Mat3)) {
    for &(v, wv) in weights {
        for &(w, ww) in weights {
            if v >= w && wv * ww != 0.0 {
                out(v, w, Mat3::IDENTITY * (m * wv * ww));
            }
        }
    }
}

/// The scalar CSC pattern (lower triangle) of the blocks in `index`, and where each
/// block's values go.
fn pattern(
    index: &HashMap<(u32, u32), usize>,
    nodes: usize,
) -> (Vec<usize>, Vec<usize>, Vec<[u32; 9]>) {
    let mut by_col: Vec<Vec<(u32, usize)>> = vec![Vec::new(); nodes];
    for (&(v, w), &k) in index {
        by_col[w as usize].push((v, k));
    }
    let mut col_ptr = vec![0usize];
    let mut row_idx = Vec::new();
    let mut position = vec![[u32::MAX; 9]; index.len()];
    for (w, rows) in by_col.iter_mut().enumerate() {
        rows.sort_unstable();
        for c in 0..3 {
            let col = 3 * w + c;
            for &(v, k) in rows.iter() {
                for r in 0..3 {
                    let row = 3 * v as usize + r;
                    if row >= col {
                        position[k][3 * r + c] = row_idx.len() as u32;
                        row_idx.push(row);
                    }
                }
            }
            col_ptr.push(row_idx.len());
        }
    }
    (col_ptr, row_idx, position)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Lame;
    use crate::vbd::shape_gradients;

    fn lame() -> Lame {
        Lame {
            mu: 6.2e4,
            lambda: 5.59e5,
        }
    }

    /// The small-strain stiffness block `∂²E/∂x_a∂x_b` of a tet with shape gradients `b`:
    /// `V [μ (b_a·b_b) I + μ b_b b_aᵀ + λ b_a b_bᵀ]` (linear elasticity).
    fn rest_block(b: &[Vec3; 4], a: usize, c: usize, volume: f32, lame: Lame) -> Mat3 {
        let outer = |x: Vec3, y: Vec3| Mat3::from_cols(x * y.x, x * y.y, x * y.z);
        (Mat3::IDENTITY * (lame.mu * b[a].dot(b[c]))
            + outer(b[c], b[a]) * lame.mu
            + outer(b[a], b[c]) * lame.lambda)
            * volume
    }

    /// The coarse matrix of a block of tets against `Pᵀ A P` formed densely.
    #[test]
    fn the_coarse_matrix_is_the_galerkin_product_and_factorises() {
        let (mesh, grid, tets) = crate::implicit::coarse_grid::test_block();
        let mass = mesh.lumped_masses(1040.0);
        let b: Vec<[Vec3; 4]> = tets.iter().map(|t| shape_gradients(&t.dm_inv)).collect();
        let rest = TetTangent::at_rest(lame());
        let (sys, _) =
            CoarseSystem::at_rest(&grid, (&tets, &b), (&mass, 3600.0), &rest, None).unwrap();
        let nc = 3 * grid.count;
        // Dense Pᵀ A P.
        let mut dense = vec![0.0f64; nc * nc];
        for t in &tets {
            let b = shape_gradients(&t.dm_inv);
            for a in 0..4 {
                for c in 0..4 {
                    let k = rest_block(&b, a, c, t.volume, lame());
                    for &(v, wa) in &grid.weights[t.nodes[a] as usize] {
                        for &(w, wc) in &grid.weights[t.nodes[c] as usize] {
                            for r in 0..3 {
                                for q in 0..3 {
                                    dense[(3 * v as usize + r) * nc + 3 * w as usize + q] +=
                                        (wa * wc * k.col(q)[r]) as f64;
                                }
                            }
                        }
                    }
                }
            }
        }
        for (i, w) in grid.weights.iter().enumerate() {
            for &(v, wv) in w {
                for &(u, wu) in w {
                    for r in 0..3 {
                        dense[(3 * v as usize + r) * nc + 3 * u as usize + r] +=
                            (mass[i] * 3600.0 * wv * wu) as f64;
                    }
                }
            }
        }
        // A_c x = b solved by the factor reproduces b.
        let x: Vec<f64> = (0..nc).map(|k| ((k * 7) % 11) as f64 - 5.0).collect();
        let mut b: Vec<f64> = (0..nc)
            .map(|r| (0..nc).map(|c| dense[r * nc + c] * x[c]).sum())
            .collect();
        sys.solve(&mut b);
        let err = b
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-3, "solve off by {err}");
    }
}
