//! The host side of the GPU Newton solver's coarse level: the same coarse grid, Galerkin
//! matrix, refresh policy and release rule as the CPU's two-level preconditioner
//! (`crate::implicit`, `TwoLevel` in implicit/workspace.rs), kept on the host, and what
//! the device applies of it: `P` as per-node weights and its transpose, and `A_c⁻¹` as a
//! dense matrix computed from the sparse Cholesky factor whenever the factor changes
//! (docs/physics-notes.md, "The implicit scheme on the GPU").

use glam::Vec3;

use crate::implicit::{
    CoarseAssembly, CoarseError, CoarseGrid, CoarseRefresh, CoarseSystem, NewtonParams,
    NewtonReport, RestTet, TetTangent,
};
use crate::material::Lame;
use crate::mesh::TetMesh;
use crate::vbd::shape_gradients;

/// Most coarse nodes the device takes: its `A_c⁻¹` is dense (9 n² values, 38 MB at this
/// bound) and recomputed on the host at every refresh and release.
pub const MAX_COARSE_NODES: usize = 1024;

/// The coarse level as the host keeps it for the device.
pub(crate) struct HostCoarse {
    grid: CoarseGrid,
    system: CoarseSystem,
    /// The tets' corner pairs for a refresh (`None` under [`CoarseRefresh::Rest`]).
    assembly: Option<CoarseAssembly>,
    tets: Vec<RestTet>,
    lame: Lame,
    policy: CoarseRefresh,
    /// The tangents of the last refresh, per tet (what a release subtracts).
    used: Vec<TetTangent>,
    /// Steps since the last refresh.
    since_refresh: u32,
}

impl HostCoarse {
    /// The coarse level of `mesh` for the nodes marked `free`, as
    /// `NewtonWorkspace::new` builds it (cubes of `coarse_cell`, default four mean rest
    /// edges; `A_c = Pᵀ(M/h² + K_rest)P` factorised).
    pub fn new(
        mesh: &TetMesh,
        mass: &[f32],
        free: &[bool],
        (lame, h): (Lame, f32),
        params: &NewtonParams,
    ) -> Result<Self, CoarseError> {
        let tets = RestTet::all(mesh);
        let cell = params
            .coarse_cell
            .unwrap_or_else(|| 4.0 * mesh.mean_edge_length());
        let grid = CoarseGrid::new(&mesh.rest_positions, free, cell);
        let system = CoarseSystem::new(&grid, &tets, mass, 1.0 / (h * h), lame)?;
        let assembly = (params.coarse_refresh != CoarseRefresh::Rest).then(|| {
            let b: Vec<[Vec3; 4]> = tets.iter().map(|t| shape_gradients(&t.dm_inv)).collect();
            CoarseAssembly::new(&grid, &tets, &b, system.block_index())
        });
        Ok(HostCoarse {
            grid,
            system,
            assembly,
            tets,
            lame,
            policy: params.coarse_refresh,
            used: Vec::new(),
            since_refresh: 0,
        })
    }

    /// Coarse nodes.
    pub fn nodes(&self) -> usize {
        self.grid.count
    }

    /// The device's `coarse_map` (layout in newton_cg.wgsl): per fine node its 8 corner
    /// ids then their 8 weights' bits; per coarse node the start of its (fine node,
    /// weight bits) pairs, then one past the last; and where those starts begin.
    pub fn map(&self) -> (Vec<u32>, u32) {
        let mut out = Vec::with_capacity(16 * self.grid.weights.len());
        for w in &self.grid.weights {
            out.extend(w.iter().map(|(id, _)| *id));
            out.extend(w.iter().map(|(_, wk)| wk.to_bits()));
        }
        let (offsets, pairs) = self.grid.transposed();
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
        self.system
            .dense_inverse()
            .into_iter()
            .map(|v| v as f32)
            .collect()
    }

    /// Whether the coming step re-assembles the coarse matrix (`last`: the previous
    /// step's report), as `NewtonWorkspace::refresh_due` decides.
    pub fn refresh_due(&self, last: &NewtonReport) -> bool {
        if self.assembly.is_none() {
            return false;
        }
        match self.policy {
            CoarseRefresh::Rest => false,
            CoarseRefresh::Steps(n) => self.since_refresh >= n,
            CoarseRefresh::Products(bound) => last.cg_products > bound * last.iterations.max(1),
        }
    }

    /// Re-assemble the coarse matrix from the tangents at the displacements `u` of the
    /// tets marked `live` (mesh order) and refactorise; on an error (not positive
    /// definite) the previous factor stays. The tangents are those of the step's first
    /// iterate, as on the CPU.
    pub fn refresh(&mut self, u: &[Vec3], live: &[bool]) -> Result<(), CoarseError> {
        let lame = self.lame;
        self.used.clear();
        self.used
            .extend(self.tets.iter().map(|t| TetTangent::at(&t.strain(u), lame)));
        self.since_refresh = 0;
        let Some(assembly) = self.assembly.as_mut() else {
            return Ok(());
        };
        let used = &self.used;
        let tangent = |t: usize| live[t].then(|| &used[t]);
        self.system.refresh(assembly, tangent, false)
    }

    /// One more step since the last refresh.
    pub fn tick(&mut self) {
        self.since_refresh += 1;
    }

    /// Take released tets (mesh indices) out of the coarse matrix, as
    /// `NewtonWorkspace::release` does: their rest stiffness, or their blocks at the last
    /// refresh's tangents.
    pub fn release(&mut self, tets: &[u32]) -> Result<(), CoarseError> {
        if let (Some(assembly), false) = (&self.assembly, self.used.is_empty()) {
            return self.system.release_refreshed(assembly, tets, &self.used);
        }
        let gone: Vec<RestTet> = tets.iter().map(|&t| self.tets[t as usize]).collect();
        self.system.release(&self.grid, &gone, self.lame)
    }
}
