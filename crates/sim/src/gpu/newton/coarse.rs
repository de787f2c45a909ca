//! The host side of the GPU Newton solver's coarse level: the same coarse grid, Galerkin
//! matrix, refresh policy and release rule as the CPU's two-level preconditioner
//! (`crate::implicit`, `TwoLevel` in implicit/two_level.rs), kept on the host, and what
//! the device applies of it: `P` as per-node weights and its transpose, and `A_c⁻¹` as a
//! dense matrix computed from the sparse Cholesky factor whenever the factor changes
//! (docs/physics-notes.md, "The implicit scheme on the GPU").

use glam::Vec3;

use crate::implicit::{CoarseError, CoarseLevel, NewtonParams, NewtonReport, RestTet, TetTangent};
use crate::material::Lame;
use crate::mesh::TetMesh;
use crate::thread_team::ThreadTeam;
use crate::vbd::shape_gradients;

/// Most coarse nodes the device takes: its `A_c⁻¹` is dense (9 n² values, 38 MB at this
/// bound) and recomputed on the host at every refresh and after releases.
pub const MAX_COARSE_NODES: usize = 1024;

/// The coarse level as the host keeps it for the device.
pub(crate) struct HostCoarse {
    level: CoarseLevel,
    tets: Vec<RestTet>,
    lame: Lame,
}

impl HostCoarse {
    /// The coarse level of `mesh` for the nodes marked `free`, as
    /// `NewtonWorkspace::new` builds it ([`CoarseLevel::new`]), assembled on the host
    /// solver's `team`.
    pub fn new(
        mesh: &TetMesh,
        mass: &[f32],
        free: &[bool],
        (lame, h): (Lame, f32),
        params: &NewtonParams,
        team: Option<&ThreadTeam>,
    ) -> Result<Self, CoarseError> {
        let tets = RestTet::all(mesh);
        let b: Vec<[Vec3; 4]> = tets.iter().map(|t| shape_gradients(&t.dm_inv)).collect();
        let level = CoarseLevel::new(mesh, (&tets, &b), (mass, free), (lame, h), params, team)?;
        Ok(HostCoarse { level, tets, lame })
    }

    /// Coarse nodes.
    pub fn nodes(&self) -> usize {
        self.level.grid.count
    }

    /// Most coarse nodes the level may come to have after cuts, at most `max` (what the
    /// device buffers are sized for; [`CoarseLevel::limit_nodes`]).
    pub fn limit_nodes(&mut self, max: usize) -> usize {
        self.level.limit_nodes(max);
        self.level.max_nodes()
    }

    /// How many times the grid was rebuilt after a cut ([`CoarseLevel::generation`]).
    pub fn generation(&self) -> u32 {
        self.level.generation()
    }

    /// The most `u32`s [`HostCoarse::map`] can come to hold on `fine` nodes with at most
    /// `coarse` coarse nodes: 16 per fine node, the offsets, two per weight.
    pub fn map_capacity(fine: usize, coarse: usize) -> usize {
        16 * fine + coarse + 1 + 2 * 8 * fine
    }

    /// The device's `coarse_map` (layout in newton_cg.wgsl): per fine node its 8 corner
    /// ids then their 8 weights' bits; per coarse node the start of its (fine node,
    /// weight bits) pairs, then one past the last; and where those starts begin.
    pub fn map(&self) -> (Vec<u32>, u32) {
        let mut out = Vec::with_capacity(16 * self.level.grid.weights.len());
        for w in &self.level.grid.weights {
            out.extend(w.iter().map(|(id, _)| *id));
            out.extend(w.iter().map(|(_, wk)| wk.to_bits()));
        }
        let (offsets, pairs) = self.level.grid.transposed();
        let transpose_at = out.len() as u32;
        let first = transpose_at + offsets.len() as u32;
        out.extend(offsets.iter().map(|&o| first + 2 * o));
        for &(i, wk) in pairs {
            out.push(i);
            out.push(wk.to_bits());
        }
        (out, transpose_at)
    }

    /// `A_c⁻¹`, dense, in f32 for the device.
    pub fn inverse(&self) -> Vec<f32> {
        self.level
            .system
            .dense_inverse()
            .into_iter()
            .map(|v| v as f32)
            .collect()
    }

    /// Whether the coming step re-assembles the coarse matrix (`last`: the previous
    /// step's report), as the CPU decides ([`CoarseLevel::refresh_due`]).
    pub fn refresh_due(&self, last: &NewtonReport) -> bool {
        self.level.refresh_due(last)
    }

    /// Re-assemble the coarse matrix from the tangents at the displacements `u` of the
    /// tets marked `live` (mesh order) and refactorise; on an error (not positive
    /// definite) the previous factor stays. The tangents are those of the step's first
    /// iterate, as on the CPU; computed on the host solver's `team` (the sums run in fixed
    /// parts, so the result does not depend on its size).
    pub fn refresh(
        &mut self,
        u: &[Vec3],
        live: &[bool],
        team: Option<&ThreadTeam>,
    ) -> Result<(), CoarseError> {
        let (lame, tets) = (self.lame, &self.tets);
        let tangent = |t: usize| TetTangent::at(&tets[t].strain(u), lame);
        self.level.refresh(tangent, live, team)
    }

    /// One more step since the last refresh.
    pub fn tick(&mut self) {
        self.level.tick();
    }

    /// Take released tets (mesh indices) out of the coarse matrix, as
    /// `NewtonWorkspace::release` does ([`CoarseLevel::release`]); refactorised by
    /// [`HostCoarse::settle`].
    pub fn release(&mut self, tets: &[u32]) {
        self.level.release(tets);
    }

    /// Refactorise after releases unless the coming step refreshes anyway
    /// ([`CoarseLevel::settle_ahead`], as `NewtonWorkspace::settle_coarse` does); whether
    /// the factor changed.
    pub fn settle(&mut self, last: &NewtonReport) -> bool {
        self.level.settle_ahead(last)
    }
}
