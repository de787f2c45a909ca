//! The coarse level of the Newton step's two-level preconditioner as the CPU
//! (`two_level.rs`) and the device (`crate::gpu::newton`) both keep it: the coarse grid,
//! its Galerkin matrix and factor, the refresh policy, the release rule and the rebuild
//! after a cut (docs/physics-notes.md, "The implicit scheme", "The coarse level after a
//! cut").

use std::sync::Arc;

use glam::Vec3;

use super::coarse_assembly::CoarseAssembly;
use super::coarse_grid::CoarseGrid;
use super::coarse_rebuild::{PendingRebuild, RebuildInputs};
use super::coarse_system::{CoarseError, CoarseSystem};
use super::newton_report::NewtonReport;
use super::params::{CoarseRefresh, NewtonParams};
use super::rest_tet::RestTet;
use super::tet_tangent::TetTangent;
use crate::material::Lame;
use crate::mesh::TetMesh;
use crate::thread_team::{ThreadTeam, for_each_item};

/// The coarse grid, its factorised matrix and what a refresh or a release needs.
pub struct CoarseLevel {
    /// Cubes of `coarse_cell` and their interpolation `P`.
    pub grid: CoarseGrid,
    /// `A_c`, factorised.
    pub system: CoarseSystem,
    /// The tets' corner pairs for re-assembling `system`.
    assembly: CoarseAssembly,
    policy: CoarseRefresh,
    /// The tangents of the last refresh (the rest tangent before any), per tet: what a
    /// release subtracts.
    used: Vec<TetTangent>,
    /// Per tet, whether the matrix holds its blocks at `used` (live at the last refresh
    /// and not released since).
    in_coarse: Vec<bool>,
    /// Steps since the last refresh.
    since_refresh: u32,
    /// What a rebuild of the grid after a cut reads (`None` under [`CoarseRefresh::Rest`]).
    rebuild_inputs: Option<Arc<RebuildInputs>>,
    /// The rebuild under way, taken at the next refresh.
    pending: Option<PendingRebuild>,
    /// A tet was released since the last rebuild started.
    cut: bool,
    /// Most coarse nodes a rebuilt grid may have (a larger one is not taken).
    max_nodes: usize,
    /// How many times the grid was rebuilt (what a copy of it, on the device, compares).
    generation: u32,
    /// Tets left the matrix since it was last factorised ([`CoarseLevel::settle`]).
    stale: bool,
}

/// How many more coarse nodes than the uncut body's a rebuilt grid may have: one half.
const SPLIT_GROWTH: usize = 2;

/// Fewest tets in a part of the refresh's pass over the tangents.
const DEFINITE_TETS: usize = 1024;

impl CoarseLevel {
    /// The coarse level of `mesh` (its `tets` with shape gradients `b`) for the nodes
    /// marked `free`, step length `h`: cubes of `coarse_cell` (default four mean rest
    /// edges), `A_c = Pᵀ(M/h² + K_rest)P` factorised (assembled on `team`'s threads).
    pub fn new(
        mesh: &TetMesh,
        (tets, b): (&[RestTet], &[[Vec3; 4]]),
        (mass, free): (&[f32], &[bool]),
        (lame, h): (Lame, f32),
        params: &NewtonParams,
        team: Option<&ThreadTeam>,
    ) -> Result<Self, CoarseError> {
        let cell = params
            .coarse_cell
            .unwrap_or_else(|| 4.0 * mesh.mean_edge_length());
        let all = vec![true; tets.len()];
        let grid = CoarseGrid::new(&mesh.rest_positions, free, cell, (tets, &all));
        let inv_h2 = 1.0 / (h * h);
        let rest = TetTangent::at_rest(lame).definite();
        let (system, assembly) =
            CoarseSystem::at_rest(&grid, (tets, b), (mass, inv_h2), &rest, team)?;
        Ok(CoarseLevel {
            system,
            assembly,
            policy: params.coarse_refresh,
            used: vec![rest; tets.len()],
            in_coarse: all,
            since_refresh: 0,
            rebuild_inputs: (params.coarse_refresh != CoarseRefresh::Rest).then(|| {
                Arc::new(RebuildInputs {
                    points: mesh.rest_positions.clone(),
                    free: free.to_vec(),
                    mass: mass.to_vec(),
                    inv_h2,
                    cell,
                    tets: tets.to_vec(),
                    b: b.to_vec(),
                })
            }),
            pending: None,
            cut: false,
            max_nodes: grid.count + grid.count / SPLIT_GROWTH,
            generation: 0,
            stale: false,
            grid,
        })
    }

    /// Most coarse nodes the grid may come to have after cuts.
    pub fn max_nodes(&self) -> usize {
        self.max_nodes
    }

    /// Lower [`CoarseLevel::max_nodes`] to `max` (what a device allocated room for).
    pub fn limit_nodes(&mut self, max: usize) {
        self.max_nodes = self.max_nodes.min(max).max(self.grid.count);
    }

    /// How many times the grid was rebuilt after a cut.
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// Whether the coming step re-assembles the matrix ([`CoarseRefresh`]; `last`: the
    /// previous step's report).
    pub fn refresh_due(&self, last: &NewtonReport) -> bool {
        match self.policy {
            CoarseRefresh::Rest => false,
            CoarseRefresh::Steps(n) => self.since_refresh >= n,
            CoarseRefresh::Products(bound) => last.cg_products > bound * last.iterations.max(1),
        }
    }

    /// One more step since the last refresh.
    pub fn tick(&mut self) {
        self.since_refresh += 1;
    }

    /// Re-assemble the matrix from the positive semi-definite part
    /// ([`TetTangent::definite`]) of `tangent(t)` (mesh order) of the tets marked `live`
    /// and refactorise, the tangents and the sums shared by the members of `team`; on an
    /// error (not positive definite) the previous factor stays, while the blocks are these
    /// tangents'. First the rebuild started at the last refresh is taken, and where tets
    /// were released since, the next one starts (`coarse_rebuild.rs`).
    pub fn refresh(
        &mut self,
        tangent: impl Fn(usize) -> TetTangent + Sync,
        live: &[bool],
        team: Option<&ThreadTeam>,
    ) -> Result<(), CoarseError> {
        let rebuilt = self.take_rebuild();
        self.start_rebuild(live);
        // One tangent per tet since `new`, each overwritten here.
        debug_assert_eq!(self.used.len(), live.len());
        for_each_item(team, &mut self.used, DEFINITE_TETS, |t, out| {
            *out = tangent(t).definite();
        });
        self.in_coarse.clear();
        self.in_coarse.extend_from_slice(live);
        self.since_refresh = 0;
        let used = &self.used;
        let tangent = |t: usize| live[t].then(|| &used[t]);
        let refreshed = self.system.refresh(&mut self.assembly, tangent, team);
        self.stale = false;
        rebuilt.and(refreshed)
    }

    /// Take the rebuild under way, if any: its grid, pattern and assembly replace these
    /// (the matrix holds the mass alone until the refresh that follows fills it).
    fn take_rebuild(&mut self) -> Result<(), CoarseError> {
        let Some(pending) = self.pending.take() else {
            return Ok(());
        };
        if let Some(rebuilt) = pending.take()? {
            self.grid = rebuilt.grid;
            self.system = rebuilt.system;
            self.assembly = rebuilt.assembly;
            self.generation += 1;
        }
        Ok(())
    }

    /// Start rebuilding on the pieces the tets marked `live` leave, where a tet was
    /// released since the last rebuild started.
    fn start_rebuild(&mut self, live: &[bool]) {
        let Some(inputs) = self.rebuild_inputs.as_ref().filter(|_| self.cut) else {
            return;
        };
        self.cut = false;
        self.pending = Some(PendingRebuild::start(
            Arc::clone(inputs),
            live.to_vec(),
            self.grid.weights.clone(),
            self.max_nodes,
        ));
    }

    /// Take released tets (mesh indices) out of the matrix: their blocks at the tangents
    /// of the last refresh (the rest tangent before any) — only those it holds (a tet
    /// released by a check earlier in the frame may have been left out of a refresh since).
    /// The factor follows at [`CoarseLevel::settle`] (or the next refresh), so a frame's
    /// releases cost no time before its state is shown.
    pub fn release(&mut self, tets: &[u32]) {
        let in_coarse = &mut self.in_coarse;
        let held: Vec<u32> = tets
            .iter()
            .copied()
            .filter(|&t| std::mem::take(&mut in_coarse[t as usize]))
            .collect();
        self.cut |= !tets.is_empty();
        self.stale |= !held.is_empty();
        self.system.subtract(&self.assembly, &held, &self.used);
    }

    /// Refactorise the matrix where tets left it since the last factorisation (the
    /// previous factor stays where this fails: the coarse level only preconditions);
    /// whether there was one to do.
    pub fn settle(&mut self) -> Result<bool, CoarseError> {
        if !std::mem::take(&mut self.stale) {
            return Ok(false);
        }
        self.system.refactor().map(|()| true)
    }

    /// [`CoarseLevel::settle`] unless the coming step re-assembles the matrix anyway
    /// (`last`: the previous step's report), as a caller does ahead of the frame; whether
    /// the factor changed (a failed refactorisation keeps the old one: the level only
    /// preconditions).
    pub fn settle_ahead(&mut self, last: &NewtonReport) -> bool {
        !self.refresh_due(last) && self.settle().unwrap_or(false)
    }
}
