//! The XPBD small-steps solver (PHYSICS.md §1.2): prediction, pins and grabs, coloured
//! Gauss-Seidel projection of the Neo-Hookean constraints, velocity update and damping;
//! per frame: stress (§1.3), release (§1.4) and the NaN / inversion guards.

use std::time::Instant;

use glam::{Mat3, Quat, Vec3};

use super::coloring::greedy_tet_colors;
use super::lane_slots::LaneSlots;
use super::locality::TetOrder;
use super::neo_hookean::{ConstraintPair, TetTerms, deformation_gradient_from_displacement};
use super::node_records::{self, NodeRecord};
use super::release_schedule::release_checks;
use super::run_projector::{RunProjector, SharedLambdas};
use super::shared_nodes::SharedNodes;
use super::stability::{MAX_STIFFNESS_NUMBER, stiffness_number, substeps_needed};
use super::sweep_plan::{SweepPlan, tet_groups};
use super::tet_slot::TetSlot;
use super::{CpuSweep, FrameStats, SolverError, SolverParams};
use crate::contact::{ContactTool, CutZone, ToolMotion, ToolPose, project_node};
use crate::cutting::{CutState, ReleaseEvent};
use crate::grab::Grab;
use crate::implicit::{NewtonReport, NewtonWorkspace, Scheme};
use crate::material::{Lame, Material};
use crate::mesh::TetMesh;
use crate::stress::{StressMeasure, cauchy_stress, tet_stress, von_mises};
use crate::thread_team::{ThreadTeam, for_each_zip3};
use crate::xpbd::{Strain, displacement_gradient};

/// Tets of a colour per part the team's members claim (a colour of fewer is one part):
/// enough to amortise a claim, few enough that the members even out.
const TEAM_PART_TETS: usize = 128;

/// Fewest nodes a part of a per-node pass (prediction, velocities) holds.
const TEAM_PART_NODES: usize = 256;

/// How a node moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// Integrated by the solver.
    Free,
    /// Fixed at its initial position.
    Pinned,
    /// Moved kinematically by grab number `n`.
    Grabbed(u32),
    /// No live tet left: frozen and hidden.
    Retired,
}

/// Solver state for one soft body.
pub struct Solver {
    pub(crate) mesh: TetMesh,
    pub(crate) lame: Lame,
    pub(crate) params: SolverParams,
    /// World positions `X + u`, refreshed at the end of every frame.
    pub(crate) x: Vec<Vec3>,
    /// Displacements from rest `u = x − X`: the solver's state. Solving for u keeps f32
    /// increments of h²g (tens of nm at hundreds of substeps) representable wherever the
    /// body sits, and `F = I + Du Dm⁻¹` never subtracts large coordinates.
    pub(crate) u: Vec<Vec3>,
    pub(crate) u_prev: Vec<Vec3>,
    /// The sweep's copy of `u` and `inv_mass`, a 16-byte record a node (kept between
    /// sweeps only so as not to allocate one each).
    pub(crate) records: Vec<NodeRecord>,
    pub(crate) v: Vec<Vec3>,
    pub(crate) mass: Vec<f32>,
    pub(crate) inv_mass: Vec<f32>,
    pub(crate) kind: Vec<NodeKind>,
    pub(crate) start: Vec<Vec3>,
    pub(crate) grabs: Vec<Grab>,
    pub(crate) slots: Vec<TetSlot>,
    /// Per mesh tet, whether its slot is live (the slots' flags in mesh order, kept by
    /// `set_live`): what the passes that go tet by tet read, one byte after another
    /// rather than one slot's cache line a tet.
    tet_live: Vec<bool>,
    /// The slots packed for the SIMD lanes, span by span of the sweep (lane kernels only).
    pub(crate) packed: Option<LaneSlots>,
    /// The order of the tets inside each colour and group.
    pub(crate) tet_order: TetOrder,
    pub(crate) color_ranges: Vec<std::ops::Range<usize>>,
    /// The slots of each slab and cut per colour, for the partitioned sweep.
    pub(crate) plan: SweepPlan,
    pub(crate) slot_of_tet: Vec<u32>,
    pub(crate) tet_of_slot: Vec<u32>,
    pub(crate) lambda_h: Vec<f32>,
    pub(crate) rotation: Vec<Quat>,
    pub(crate) von_mises: Vec<f32>,
    pub(crate) det_f: Vec<f32>,
    pub(crate) inverted_frames: Vec<u32>,
    pub(crate) cut: CutState,
    /// Tets switched off by a release check during the frame in hand (mesh indices); the
    /// cut state takes them when the frame has passed its guards.
    pub(crate) pending: Vec<u32>,
    /// The tool, if one is attached, and its motion over the coming frame.
    pub(crate) tool: Option<ToolMotion>,
    /// Nodes that came within the cut reach of a cutting sphere this frame.
    pub(crate) near_edge: Vec<bool>,
    /// The same since the last release check (what a `NearEdge` cut zone releases by).
    pub(crate) near_window: Vec<bool>,
    /// Per node, Σ m Δx of the contact projections this frame (tissue side), kg·m; under
    /// `scheme: Newton`, h² times the force that held a node in the blade's path.
    pub(crate) contact_push: Vec<Vec3>,
    /// Nodes the tool held through the last implicit step's solve (`scheme: Newton`): the
    /// next step starts them where they were, on the blade.
    pub(crate) touched: Vec<bool>,
    pub(crate) frame: u64,
    pub(crate) time: f64,
    /// Wall time of the release checks inside the last frame's substeps, ms.
    pub(crate) check_ms: f64,
    /// Parallel passes of the last frame (colours per substep, stress passes).
    pub(crate) passes: u32,
    /// What the last frame's implicit steps cost (Newton).
    pub(crate) implicit_cost: crate::implicit::FrameCost,
    /// Coarse nodes after the last implicit step (0 under XPBD).
    pub(crate) coarse_nodes: u32,
    /// The threads of the solver's passes (`thread_team.rs`; `None`: one thread): the
    /// caller and a member per further core, waiting for the next pass spinning, not
    /// asleep.
    pub(crate) team: Option<ThreadTeam>,
    /// The implicit scheme's buffers and preconditioner, built at its first step (when
    /// the pins and grabs are known).
    pub(crate) newton: Option<NewtonWorkspace>,
    /// Wall time of the coming frame's work done ahead of it (`Solver::prepare_frame`), ms.
    pub(crate) ahead_ms: f64,
}

/// The team for `threads` solver threads (0: one per core; 1: none, every pass on the
/// caller's thread), at most one member per core: a member that waits spinning for a core
/// another member holds would stall every pass.
fn solver_team(threads: usize) -> Result<Option<ThreadTeam>, SolverError> {
    if threads == 1 {
        return Ok(None);
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let size = if threads == 0 {
        cores
    } else {
        threads.min(cores)
    };
    let team = ThreadTeam::new(size).map_err(|e| SolverError::ThreadPool {
        threads: size,
        msg: e.to_string(),
    })?;
    Ok(Some(team))
}

impl Solver {
    /// A solver for `mesh` made of `material`, starting at rest.
    pub fn new(
        mesh: TetMesh,
        material: Material,
        params: SolverParams,
    ) -> Result<Self, SolverError> {
        Self::with_tet_order(mesh, material, params, TetOrder::default())
    }

    /// [`Solver::new`] with the tets of each colour stored in `order` (the same results
    /// in any order: tests and measurement).
    pub fn with_tet_order(
        mesh: TetMesh,
        material: Material,
        params: SolverParams,
        tet_order: TetOrder,
    ) -> Result<Self, SolverError> {
        material.validate()?;
        params.validate()?;
        params.check_material(&material)?;
        let lame = material.lame();
        let (colors, ncolors) = greedy_tet_colors(mesh.node_count(), &mesh.tets);
        // Colour first (the coloured sweep and the GPU), then the sweep plan's group, then
        // by lowest node (`xpbd/locality.rs`): inside a colour the order changes no result.
        let groups = tet_groups(&mesh.rest_positions, &mesh.tets);
        let near = tet_order.keys(&mesh.tets);
        let mut order: Vec<u32> = (0..mesh.tet_count() as u32).collect();
        order.sort_by_key(|&t| (colors[t as usize], groups[t as usize], near[t as usize], t));
        let keys: Vec<(u32, u32)> = order
            .iter()
            .map(|&t| (colors[t as usize], groups[t as usize]))
            .collect();
        let plan = SweepPlan::new(&keys, ncolors);
        let color_ranges = plan.colour_ranges();
        let mut slot_of_tet = vec![0u32; mesh.tet_count()];
        for (s, &t) in order.iter().enumerate() {
            slot_of_tet[t as usize] = s as u32;
        }
        let mass = mesh.lumped_masses(material.density);
        let inv_mass: Vec<f32> = mass
            .iter()
            .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
            .collect();
        // Implicit Euler has no step bound; only the XPBD small steps do.
        if params.scheme == Scheme::Xpbd {
            let (kappa, tet) = stiffness_number(&mesh, &inv_mass, lame, params.substep());
            if kappa > MAX_STIFFNESS_NUMBER {
                return Err(SolverError::Unstable {
                    h_ms: params.substep() * 1e3,
                    tet,
                    kappa,
                    max: MAX_STIFFNESS_NUMBER,
                    needed: substeps_needed(kappa, params.substeps),
                });
            }
        }
        let team = solver_team(params.threads)?;
        let n = mesh.node_count();
        let t = mesh.tet_count();
        let mut solver = Solver {
            x: mesh.rest_positions.clone(),
            u: vec![Vec3::ZERO; n],
            u_prev: vec![Vec3::ZERO; n],
            records: Vec::new(),
            start: vec![Vec3::ZERO; n],
            v: vec![Vec3::ZERO; n],
            mass,
            inv_mass,
            kind: vec![NodeKind::Free; n],
            grabs: Vec::new(),
            slots: Vec::new(),
            tet_live: vec![true; t],
            packed: None,
            tet_order,
            color_ranges,
            plan,
            slot_of_tet,
            tet_of_slot: order.clone(),
            lambda_h: vec![0.0; t],
            rotation: vec![Quat::IDENTITY; t],
            von_mises: vec![0.0; t],
            det_f: vec![1.0; t],
            inverted_frames: vec![0; t],
            cut: CutState::new(&mesh),
            pending: Vec::new(),
            tool: None,
            near_edge: vec![false; n],
            near_window: vec![false; n],
            contact_push: vec![Vec3::ZERO; n],
            touched: vec![false; n],
            frame: 0,
            time: 0.0,
            check_ms: 0.0,
            passes: 0,
            implicit_cost: Default::default(),
            coarse_nodes: 0,
            team,
            newton: None,
            ahead_ms: 0.0,
            lame,
            params,
            mesh,
        };
        // Nodes in no tet have no mass: they are not simulated (PHYSICS.md §1.1 masses).
        for (k, m) in solver.kind.iter_mut().zip(&solver.mass) {
            if *m <= 0.0 {
                *k = NodeKind::Retired;
            }
        }
        solver.slots = order
            .iter()
            .map(|&t| TetSlot {
                nodes: solver.mesh.tets[t as usize],
                terms: solver.terms(t as usize),
                live: true,
            })
            .collect();
        // Only the XPBD sweep projects the packed blocks.
        let sweeps = solver.params.scheme == Scheme::Xpbd;
        solver.packed = RunProjector::lane_kernel(&solver.params)
            .filter(|_| sweeps)
            .map(|_| {
                let spans: Vec<_> = match solver.params.cpu_sweep {
                    CpuSweep::Coloured => solver.color_ranges.clone(),
                    CpuSweep::Blocks => solver.plan.runs.iter().flatten().cloned().collect(),
                };
                LaneSlots::new(&solver.slots, spans)
            });
        Ok(solver)
    }

    /// Per mesh tet, whether it is live in the sweep now (its slot: release checks inside
    /// a frame switch tets off here before the cut state hears of them).
    pub(crate) fn live_tets(&self) -> Vec<bool> {
        self.tet_live.clone()
    }

    /// Switch mesh tet `t` on or off in the sweep (its slot and packed lane).
    fn set_live(&mut self, t: u32, live: bool) {
        let s = self.slot_of_tet[t as usize] as usize;
        self.slots[s].live = live;
        self.tet_live[t as usize] = live;
        if let Some(p) = &mut self.packed {
            p.set_live(s, live);
        }
    }

    /// Compliance terms of tet `t` for the current substep length.
    fn terms(&self, t: usize) -> TetTerms {
        let h = self.params.substep();
        let v = self.mesh.rest_volume[t];
        TetTerms {
            dm_inv: self.mesh.dm_inv[t],
            // PHYSICS.md §1.2: α_H = 1/(λ_H V), α_D = 1/(μV), α̃ = α/h². λ_H is λ for the
            // rest-free pair (infinite compliance at ν = 0: no volume constraint), see
            // `Lame::hydrostatic` for the γ-shifted one.
            alpha_h: 1.0 / (self.volume_stiffness() * v * h * h),
            alpha_d: 1.0 / (self.lame.mu * v * h * h),
            gamma: self.lame.gamma(self.params.hydrostatic),
        }
    }

    /// Stiffness of the volume constraint, Pa: λ (rest-free) or λ_H (γ-shifted).
    pub fn volume_stiffness(&self) -> f32 {
        match self.params.constraints {
            ConstraintPair::RestFree => self.lame.lambda,
            ConstraintPair::GammaShifted => self.lame.hydrostatic(self.params.hydrostatic),
        }
    }

    /// The mesh being simulated (rest state and topology).
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// Settings in use.
    pub fn params(&self) -> &SolverParams {
        &self.params
    }

    /// Lamé parameters in use.
    pub fn lame(&self) -> Lame {
        self.lame
    }

    /// Current node positions, m.
    pub fn positions(&self) -> &[Vec3] {
        &self.x
    }

    /// Replace all node positions (e.g. to start from a deformed state); velocities are zeroed.
    pub fn set_positions(&mut self, x: &[Vec3]) {
        for (i, p) in x.iter().enumerate() {
            self.u[i] = *p - self.mesh.rest_positions[i];
        }
        self.u_prev.copy_from_slice(&self.u);
        self.start.copy_from_slice(&self.u);
        self.v.iter_mut().for_each(|v| *v = Vec3::ZERO);
        self.sync_positions();
    }

    /// Current node velocities, m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.v
    }

    /// Replace the free nodes' velocities, m/s (to carry a moving state into a rebuilt
    /// solver, after [`Solver::set_positions`] zeroed them); pinned, grabbed and retired
    /// nodes keep theirs.
    pub fn set_velocities(&mut self, v: &[Vec3]) {
        for ((dst, src), kind) in self.v.iter_mut().zip(v).zip(&self.kind) {
            if *kind == NodeKind::Free {
                *dst = *src;
            }
        }
    }

    /// The fewest substeps per frame the stability bound allows (κ ≤
    /// [`MAX_STIFFNESS_NUMBER`] at the worst tet, from every node's own mass, as
    /// [`Solver::new`] checks it).
    pub fn fewest_stable_substeps(&self) -> u32 {
        let inv_mass: Vec<f32> = self
            .mass
            .iter()
            .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
            .collect();
        let (kappa, _) = stiffness_number(&self.mesh, &inv_mass, self.lame, self.params.substep());
        substeps_needed(kappa, self.params.substeps)
    }

    /// Lumped node masses, kg.
    pub fn masses(&self) -> &[f32] {
        &self.mass
    }

    /// How each node moves.
    pub fn node_kinds(&self) -> &[NodeKind] {
        &self.kind
    }

    /// The pinned nodes' indices, ascending.
    pub fn pinned_nodes(&self) -> Vec<u32> {
        self.kind
            .iter()
            .enumerate()
            .filter(|(_, k)| **k == NodeKind::Pinned)
            .map(|(i, _)| i as u32)
            .collect()
    }

    /// von Mises stress per tet (mesh order) as of the last frame, Pa.
    pub fn von_mises(&self) -> &[f32] {
        &self.von_mises
    }

    /// det F per tet (mesh order) as of the last frame.
    pub fn det_f(&self) -> &[f32] {
        &self.det_f
    }

    /// Cut state: live tets, visible faces, retired nodes.
    pub fn cut(&self) -> &CutState {
        &self.cut
    }

    /// Number of tet colours (parallel passes per substep).
    pub fn color_count(&self) -> usize {
        self.color_ranges.len()
    }

    /// Mesh tet of each slot: the order the solver and the GPU keep per-tet data in
    /// (colour, then the partitioned sweep's group, then lowest node unless built in
    /// [`TetOrder::Mesh`], then mesh index: `xpbd/locality.rs`).
    pub fn slot_tets(&self) -> &[u32] {
        &self.tet_of_slot
    }

    /// Tets in each phase of the partitioned sweep: the slab blocks, the even cuts, the odd
    /// cuts and the tets across more than two slabs (`CpuSweep::Blocks`).
    pub fn sweep_phase_sizes(&self) -> Vec<usize> {
        self.plan.phase_sizes()
    }

    /// Frames stepped so far.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Simulation time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Fix `nodes` at their current positions.
    pub fn pin(&mut self, nodes: &[u32]) {
        for &i in nodes {
            self.kind[i as usize] = NodeKind::Pinned;
            self.inv_mass[i as usize] = 0.0;
            self.v[i as usize] = Vec3::ZERO;
        }
    }

    /// Add a scripted grab; its nodes become kinematic and follow its path from their
    /// current positions.
    pub fn add_grab(&mut self, grab: Grab) {
        let id = self.grabs.len() as u32;
        for &i in &grab.nodes {
            self.kind[i as usize] = NodeKind::Grabbed(id);
            self.inv_mass[i as usize] = 0.0;
            self.start[i as usize] = self.u[i as usize];
        }
        self.grabs.push(grab);
    }

    /// Attach a tool at `pose` (replacing any previous one); it stays there until
    /// [`Solver::move_tool`] moves it.
    pub fn set_tool(&mut self, tool: ContactTool, pose: ToolPose) -> Result<(), SolverError> {
        tool.validate()?;
        self.tool = Some(ToolMotion {
            tool,
            from: pose,
            to: pose,
        });
        Ok(())
    }

    /// Where the tool will be at the end of the next frame; it moves there continuously
    /// over the frame's substeps (translation lerp, rotation slerp). No tool: ignored.
    pub fn move_tool(&mut self, to: ToolPose) {
        if let Some(m) = &mut self.tool {
            m.to = to;
        }
    }

    /// Detach the tool.
    pub fn remove_tool(&mut self) {
        self.tool = None;
    }

    /// The attached tool and its current motion.
    pub fn tool(&self) -> Option<&ToolMotion> {
        self.tool.as_ref()
    }

    /// Nodes that came within the cut reach of a cutting sphere during the last frame.
    pub fn near_edge(&self) -> &[bool] {
        &self.near_edge
    }

    /// Fault injection for tests: give free node `node` a NaN velocity, as a solver bug
    /// would; the next frame must stop with `SolverError::NonFinite` and roll back.
    pub fn inject_non_finite(&mut self, node: usize) {
        if let Some(v) = self.v.get_mut(node) {
            *v = Vec3::NAN;
        }
    }

    /// Release tets by hand (mesh indices); returns what changed.
    pub fn release(&mut self, tets: &[u32]) -> ReleaseEvent {
        let ev = self.cut.release(&self.mesh, tets);
        for &t in &ev.tets {
            self.set_live(t, false);
        }
        if let Some(ws) = &mut self.newton {
            ws.release(&ev.tets);
        }
        for &n in &ev.retired_nodes {
            self.kind[n as usize] = NodeKind::Retired;
            self.inv_mass[n as usize] = 0.0;
            self.v[n as usize] = Vec3::ZERO;
        }
        ev
    }

    /// Advance one frame: `substeps` XPBD substeps with the release checks that fall in
    /// them, then stress, guards, and the frame's releases handed to the cut state.
    ///
    /// On a NaN/Inf position or a tet inverted for longer than `max_inverted_frames`, the
    /// frame is rolled back (tets switched off during it come back) and an error names the
    /// frame and the tet.
    pub fn step_frame(&mut self) -> Result<FrameStats, SolverError> {
        let saved = (self.u.clone(), self.v.clone(), self.touched.clone());
        let t0 = Instant::now();
        self.near_edge.iter_mut().for_each(|b| *b = false);
        self.contact_push.iter_mut().for_each(|p| *p = Vec3::ZERO);
        let fresh = match self.params.scheme {
            Scheme::Xpbd => self.run_substeps(),
            Scheme::Newton(p) => {
                let start = (&saved.0[..], &saved.1[..], &saved.2[..]);
                self.run_implicit_steps(p, start)?
            }
        };
        self.time += self.params.frame_dt as f64;
        self.sync_positions();
        let t1 = Instant::now();
        let checked = self.update_stress_and_check(fresh);
        if let Err(e) = checked {
            self.u = saved.0;
            self.u_prev.clone_from(&self.u);
            self.v = saved.1;
            self.touched = saved.2;
            self.sync_positions();
            self.time -= self.params.frame_dt as f64;
            self.revive_pending();
            return Err(e);
        }
        let pending = std::mem::take(&mut self.pending);
        let released = if pending.is_empty() {
            0
        } else {
            self.release(&pending).tets.len()
        };
        if let Some(m) = &mut self.tool {
            m.from = m.to;
        }
        let mut stats = self.stats(released);
        stats.solve_ms = (t1 - t0).as_secs_f64() * 1e3;
        stats.check_ms = self.check_ms;
        stats.stress_ms = t1.elapsed().as_secs_f64() * 1e3;
        stats.ahead_ms = std::mem::take(&mut self.ahead_ms);
        self.frame += 1;
        Ok(stats)
    }

    /// Switch the tets of a rolled-back frame's release checks back on.
    pub(crate) fn revive_pending(&mut self) {
        for t in std::mem::take(&mut self.pending) {
            self.set_live(t, true);
        }
    }

    /// The frame's substeps; after each substep in which a release check falls, stress
    /// and release (PHYSICS.md §1.4 on a fixed simulation-time interval). Returns whether
    /// the stress is current for the end of the frame (a check ran after the last
    /// substep).
    fn run_substeps(&mut self) -> bool {
        let h = self.params.substep();
        let n = self.params.substeps;
        let checks = release_checks(self.time, h, n, self.params.release_interval);
        let mut next = checks.iter().peekable();
        let mut fresh = false;
        self.check_ms = 0.0;
        let per_sweep = match self.params.cpu_sweep {
            CpuSweep::Coloured => self.color_ranges.len(),
            CpuSweep::Blocks => self.plan.phases.len(),
        };
        self.passes = n * per_sweep as u32 + checks.len() as u32;
        for s in 0..n {
            let t = self.time + (s + 1) as f64 * h as f64;
            self.predict(h, t);
            self.sweep();
            self.project_contacts(s, n);
            self.update_velocities(h);
            fresh = next.next_if(|&&k| k == s).is_some();
            if fresh {
                self.release_check();
            }
        }
        fresh
    }

    /// Stress, then the tets over the threshold switched off (PHYSICS.md §1.4), timed.
    pub(crate) fn release_check(&mut self) {
        let t0 = Instant::now();
        self.compute_stress();
        self.switch_off_overstressed();
        self.check_ms += t0.elapsed().as_secs_f64() * 1e3;
    }

    /// The threads the solver's passes run on: its team's members (the caller among
    /// them), 1 without a team.
    pub fn threads(&self) -> usize {
        self.team.as_ref().map_or(1, ThreadTeam::size)
    }

    /// The implicit scheme's last step: Newton iterations and conjugate-gradient products
    /// (`None` under XPBD or before the first frame).
    pub fn newton_report(&self) -> Option<NewtonReport> {
        self.newton.as_ref().map(|w| w.last)
    }

    /// Push free nodes out of the tool as it moves through substep `s` of `n`
    /// (PHYSICS.md §1.5, `C = d(x) ≥ 0`, zero compliance: `Δλ = m·|Δx|`).
    ///
    /// Projected after the tet constraints, not before as PHYSICS.md §1.2 lists them:
    /// with one iteration per substep the last projection is the one that holds, and
    /// this way every substep ends with no node inside the tool.
    pub(crate) fn project_contacts(&mut self, s: u32, n: u32) {
        for (i, pushed) in self.contacts(s, n) {
            self.contact_push[i] += self.mass[i] * pushed;
        }
    }

    /// Project every free node out of the tool over substep (or implicit step) `s` of `n`,
    /// flagging the nodes near its edge; the nodes moved and by how much.
    pub(crate) fn contacts(&mut self, s: u32, n: u32) -> Vec<(usize, Vec3)> {
        let Some(motion) = &self.tool else {
            return Vec::new();
        };
        let from = motion.placed_at(s, n);
        let to = motion.placed_at(s + 1, n);
        let friction = motion.tool.friction;
        let reach = match self.params.cut_zone {
            CutZone::NearEdge { reach } => Some(reach),
            CutZone::Anywhere => None,
        };
        let mut moved = Vec::new();
        for i in 0..self.u.len() {
            if self.kind[i] != NodeKind::Free {
                continue;
            }
            let rest = self.mesh.rest_positions[i];
            let x = rest + self.u[i];
            let c = project_node(rest + self.u_prev[i], x, &from, &to, friction, reach);
            if c.moved {
                self.u[i] = c.x - rest;
                moved.push((i, c.x - x));
            }
            self.near_edge[i] |= c.near_edge;
            self.near_window[i] |= c.near_edge;
        }
        moved
    }

    /// The blade in the implicit step `s` of `n` (`scheme: Newton`), before its solve: the
    /// nodes it held in the last step start where they were, every free node is
    /// projected out of the tool's path, and those it moved are marked `held` (the solve
    /// keeps them fixed, so the tissue around them answers the push within the step).
    pub(crate) fn hold_contacts(&mut self, s: u32, n: u32, held: &mut [bool]) {
        if self.tool.is_none() {
            return;
        }
        for i in 0..self.u.len() {
            if std::mem::take(&mut self.touched[i]) && self.kind[i] == NodeKind::Free {
                self.u[i] = self.u_prev[i];
            }
        }
        for (i, _) in self.contacts(s, n) {
            held[i] = true;
        }
    }

    /// `v += h g; u_prev = u; u += h v` for free nodes; kinematic nodes jump to their
    /// target at the end of the substep.
    // PHYSICS.md §1.2, small-steps loop, prediction.
    pub(crate) fn predict(&mut self, h: f32, t: f64) {
        let offsets: Vec<Vec3> = self.grabs.iter().map(|g| g.offset_at(t)).collect();
        let (g, kind, start) = (self.params.gravity, &self.kind, &self.start);
        let node = |i: usize, u: &mut Vec3, u_prev: &mut Vec3, v: &mut Vec3| {
            *u_prev = *u;
            match kind[i] {
                NodeKind::Free => {
                    *v += h * g;
                    *u += h * *v;
                }
                NodeKind::Grabbed(k) => *u = start[i] + offsets[k as usize],
                NodeKind::Pinned | NodeKind::Retired => {}
            }
        };
        let arrays = (&mut self.u[..], &mut self.u_prev[..], &mut self.v[..]);
        for_each_zip3(self.team.as_ref(), arrays, TEAM_PART_NODES, node);
    }

    /// One sweep over the live tets in the parameters' order, on the node records
    /// (`xpbd/node_records.rs`): filled from `u` and the inverse masses before it, `u`
    /// read back after it.
    fn sweep(&mut self) {
        let mut records = std::mem::take(&mut self.records);
        node_records::fill(self.team.as_ref(), &mut records, &self.u, &self.inv_mass);
        let nodes = SharedNodes::new(&mut records);
        match self.params.cpu_sweep {
            CpuSweep::Coloured => {
                for c in 0..self.color_ranges.len() {
                    self.project_color(c, &nodes);
                }
            }
            CpuSweep::Blocks => self.project_blocks(&nodes),
        }
        node_records::read_back(self.team.as_ref(), &records, &mut self.u);
        self.records = records;
    }

    /// Project every live tet of colour `c` (no two share a node), in parts shared by the
    /// team where there is one.
    fn project_color(&mut self, c: usize, nodes: &SharedNodes) {
        let range = self.color_ranges[c].clone();
        let packed = self.packed.as_ref();
        let projector = RunProjector::of(&self.params, &self.slots, packed);
        let lambdas = SharedLambdas::new(&mut self.lambda_h);
        // A colour of few tets costs less on one thread than split.
        let parts = match self.team {
            Some(_) => (range.len() / TEAM_PART_TETS).max(1),
            None => 1,
        };
        // SAFETY: tets of one colour share no node, and the parts are disjoint; this pass
        // is the only one. The packed spans of the coloured sweep are its colours.
        let part =
            |p: usize| unsafe { projector.span(c, range.clone(), &lambdas, nodes, (p, parts)) };
        match self.team.as_ref() {
            Some(team) => team.run(parts, part),
            None => part(0),
        }
    }

    /// One sweep in the partitioned order (`xpbd/sweep_plan.rs`): phase after phase, the
    /// phase's groups shared by the team, each group's tets colour after colour.
    fn project_blocks(&mut self, nodes: &SharedNodes) {
        let packed = self.packed.as_ref();
        let projector = RunProjector::of(&self.params, &self.slots, packed);
        let lambdas = SharedLambdas::new(&mut self.lambda_h);
        let (plan, colours) = (&self.plan, self.color_ranges.len());
        let group = |g: &usize| {
            for (c, r) in plan.runs[*g].iter().enumerate() {
                // SAFETY: the groups of one phase share no node (slabs and alternate
                // cuts), each run's tets are of one colour, and runs are disjoint ranges
                // of the slots. The packed spans of the partitioned sweep are its runs,
                // group by group.
                unsafe { projector.span(*g * colours + c, r.clone(), &lambdas, nodes, (0, 1)) };
            }
        };
        for phase in &plan.phases {
            match self.team.as_ref() {
                Some(team) => team.run(phase.len(), |p| group(&phase[p])),
                None => phase.iter().for_each(group),
            }
        }
    }

    /// `v = (u − u_prev)/h` (= (x − x_prev)/h), then damping.
    // PHYSICS.md §1.2, small-steps loop, velocity update.
    pub(crate) fn update_velocities(&mut self, h: f32) {
        let keep = (1.0 - self.params.damping * h).max(0.0);
        let (inv_h, kind) = (1.0 / h, &self.kind);
        let node = |i: usize, v: &mut Vec3, u: &mut Vec3, u_prev: &mut Vec3| {
            *v = match kind[i] {
                NodeKind::Free => (*u - *u_prev) * inv_h * keep,
                NodeKind::Grabbed(_) => (*u - *u_prev) * inv_h,
                NodeKind::Pinned | NodeKind::Retired => Vec3::ZERO,
            };
        };
        let arrays = (&mut self.v[..], &mut self.u[..], &mut self.u_prev[..]);
        for_each_zip3(self.team.as_ref(), arrays, TEAM_PART_NODES, node);
    }

    /// Stress and det F per live tet (unless `fresh` from a check after the last
    /// substep), then the NaN and inversion guards.
    fn update_stress_and_check(&mut self, fresh: bool) -> Result<(), SolverError> {
        self.check_finite()?;
        if !fresh {
            self.passes += 1;
            self.compute_stress();
        }
        self.check_inversion()
    }

    /// World positions `x = X + u` from the displacements.
    pub(crate) fn sync_positions(&mut self) {
        for ((x, r), u) in self
            .x
            .iter_mut()
            .zip(&self.mesh.rest_positions)
            .zip(&self.u)
        {
            *x = *r + *u;
        }
    }

    /// NaN/Inf guard on node displacements.
    pub(crate) fn check_finite(&self) -> Result<(), SolverError> {
        if let Some(node) = self.u.iter().position(|p| !p.is_finite()) {
            let tet = self.mesh.tets_of_node(node).first().copied().unwrap_or(0) as usize;
            return Err(SolverError::NonFinite {
                frame: self.frame,
                node,
                tet,
            });
        }
        Ok(())
    }

    /// σ_vM and det F of every live tet (and, for the seed's eq. 3, the polar rotation).
    fn compute_stress(&mut self) {
        let eval = TetStressEval {
            mesh: &self.mesh,
            u: &self.u,
            live: &self.tet_live,
            slot_of_tet: &self.slot_of_tet,
            lambda_h: &self.lambda_h,
            lame: self.lame,
            volume_stiffness: self.volume_stiffness(),
            pair: self.params.constraints,
            measure: self.params.stress,
            h2: self.params.substep() * self.params.substep(),
        };
        let compute = |t: usize, vm: &mut f32, d: &mut f32, r: &mut Quat| eval.tet(t, (vm, d, r));
        let arrays = (
            &mut self.von_mises[..],
            &mut self.det_f[..],
            &mut self.rotation[..],
        );
        for_each_zip3(self.team.as_ref(), arrays, TEAM_PART_TETS, compute);
    }

    /// Count consecutive inverted frames per live tet; error past the limit.
    pub(crate) fn check_inversion(&mut self) -> Result<(), SolverError> {
        let limit = self.params.max_inverted_frames;
        let mut worst: Option<(usize, u32)> = None;
        for t in 0..self.det_f.len() {
            if self.cut.is_live(t) && self.det_f[t] <= 0.0 {
                self.inverted_frames[t] += 1;
                if self.inverted_frames[t] > limit && worst.is_none() {
                    worst = Some((t, self.inverted_frames[t]));
                }
            } else {
                self.inverted_frames[t] = 0;
            }
        }
        if let Some((tet, frames)) = worst {
            return Err(SolverError::Inverted {
                frame: self.frame,
                tet,
                frames,
                det: self.det_f[tet],
            });
        }
        Ok(())
    }

    /// Switch off live tets whose von Mises stress exceeds the threshold (PHYSICS.md §1.4,
    /// eq. 5); with a `NearEdge` cut zone only those a cutting sphere came near since the
    /// last check. They join the frame's pending releases; the near-edge window restarts.
    fn switch_off_overstressed(&mut self) {
        let Some(threshold) = self.params.release_threshold else {
            return;
        };
        let near_edge = matches!(self.params.cut_zone, CutZone::NearEdge { .. });
        let over: Vec<u32> = (0..self.von_mises.len())
            .filter(|&t| self.tet_live[t])
            .filter(|&t| self.von_mises[t] > threshold)
            .filter(|&t| {
                !near_edge
                    || self.mesh.tets[t]
                        .iter()
                        .any(|&i| self.near_window[i as usize])
            })
            .map(|t| t as u32)
            .collect();
        for &t in &over {
            self.set_live(t, false);
        }
        self.pending.extend(over);
        self.near_window.iter_mut().for_each(|b| *b = false);
    }

    /// Mean force the tissue exerted on the tool over the last frame, N: the contact
    /// multipliers `f = Σ λ / h²` (PHYSICS.md §1.5), averaged over the substeps, with the
    /// sign of the reaction on the tool.
    pub fn tool_force(&self) -> Vec3 {
        let h = self.params.step_length();
        let push: Vec3 = self.contact_push.iter().sum();
        -push / (h * h * self.params.steps() as f32)
    }

    /// Frame statistics over the live tets (PHYSICS.md §1.3 stress, volume, energy).
    pub(crate) fn stats(&self, released_now: usize) -> FrameStats {
        let mut max_vm = 0.0f32;
        let mut sum_vm = 0.0f64;
        let mut live = 0usize;
        let mut vol = 0.0f64;
        let mut rest = 0.0f64;
        for t in 0..self.von_mises.len() {
            if self.cut.is_live(t) {
                live += 1;
                max_vm = max_vm.max(self.von_mises[t]);
                sum_vm += self.von_mises[t] as f64;
                let v0 = self.mesh.rest_volume[t] as f64;
                rest += v0;
                vol += v0 * self.det_f[t] as f64;
            }
        }
        let ke = self
            .v
            .iter()
            .zip(&self.mass)
            .map(|(v, &m)| 0.5 * m as f64 * v.length_squared() as f64)
            .sum();
        FrameStats {
            frame: self.frame,
            sim_time: self.time,
            substeps: self.params.steps(),
            max_von_mises: max_vm,
            mean_von_mises: if live > 0 {
                (sum_vm / live as f64) as f32
            } else {
                0.0
            },
            released_now,
            released_total: self.cut.released_count(),
            retired_nodes: self.cut.retired_count(),
            volume_ratio: if rest > 0.0 { vol / rest } else { 0.0 },
            kinetic_energy: ke,
            tool_force: self.tool_force(),
            contact_nodes: self
                .contact_push
                .iter()
                .filter(|p| **p != Vec3::ZERO)
                .count(),
            solve_ms: 0.0,
            check_ms: 0.0,
            stress_ms: 0.0,
            ahead_ms: 0.0,
            passes: self.passes,
            cg_products: self.implicit_cost.cg_products,
            newton_iterations: self.implicit_cost.iterations,
            negative_curvature: self.implicit_cost.negative_curvature,
            line_search_halvings: self.implicit_cost.halvings,
            coarse_refreshes: self.implicit_cost.coarse_refreshes,
            split_frames: self.implicit_cost.split_frames,
            coarse_nodes: self.coarse_nodes,
        }
    }
}

/// What the per-tet stress reads (shared by the parallel stress pass).
struct TetStressEval<'a> {
    mesh: &'a TetMesh,
    u: &'a [Vec3],
    /// Per mesh tet, whether it is live.
    live: &'a [bool],
    slot_of_tet: &'a [u32],
    lambda_h: &'a [f32],
    lame: Lame,
    volume_stiffness: f32,
    pair: ConstraintPair,
    measure: StressMeasure,
    h2: f32,
}

impl TetStressEval<'_> {
    /// σ_vM, det F and rotation of tet `t` (zero stress when switched off).
    fn tet(&self, t: usize, out: (&mut f32, &mut f32, &mut Quat)) {
        if !self.live[t] {
            *out.0 = 0.0;
            return;
        }
        let d = self.mesh.tets[t].map(|i| self.u[i as usize]);
        let dm_inv = &self.mesh.dm_inv[t];
        match self.measure {
            StressMeasure::Cauchy => {
                let s = Strain::of(displacement_gradient(&d, dm_inv));
                let sigma = cauchy_stress(&s, self.lame, self.pair, self.volume_stiffness);
                *out.0 = von_mises(&sigma);
                *out.1 = s.j();
            }
            StressMeasure::PaperEq3 => {
                let f: Mat3 = deformation_gradient_from_displacement(&d, dm_inv);
                let lam = self.lambda_h[self.slot_of_tet[t] as usize];
                let st = tet_stress(
                    &f,
                    self.lame.mu,
                    lam,
                    self.h2,
                    self.mesh.rest_volume[t],
                    *out.2,
                );
                *out.0 = st.von_mises;
                *out.1 = f.determinant();
                *out.2 = st.rotation;
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::generate::block;

    /// A block of `cells` cubes over `extent` m of soft tissue (E 10 kPa, ν 0.4) on
    /// `params`, 40 substeps a frame, its nodes moved by `shift` (node index → m).
    pub(crate) fn soft_block(
        (extent, cells): (Vec3, glam::UVec3),
        params: SolverParams,
        shift: impl Fn(usize) -> Vec3,
    ) -> Solver {
        let mesh = TetMesh::from_raw(block(Vec3::ZERO, extent, cells))
            .unwrap()
            .0;
        let material = Material {
            youngs_modulus: 10e3,
            poisson_ratio: 0.4,
            density: 1000.0,
        };
        let params = SolverParams {
            substeps: 40,
            ..params
        };
        let mut s = Solver::new(mesh, material, params).unwrap();
        let x: Vec<Vec3> = (s.positions().iter().enumerate())
            .map(|(i, p)| *p + shift(i))
            .collect();
        s.set_positions(&x);
        s
    }

    /// A 768-tet block on a team of two, its nodes shaken so that the stress varies
    /// from tet to tet, with a release threshold.
    fn shaken() -> Solver {
        let params = SolverParams {
            threads: 2,
            release_threshold: Some(1.2e3),
            ..SolverParams::default()
        };
        let cells = (Vec3::new(0.04, 0.02, 0.02), glam::UVec3::new(8, 4, 4));
        soft_block(cells, params, |i| Vec3::Z * 4e-4 * ((i as f32) * 0.9).sin())
    }

    /// Each mesh tet's flag in `tet_live` is its slot's.
    fn flags_agree(s: &Solver) -> bool {
        (0..s.mesh.tet_count()).all(|t| s.tet_live[t] == s.slots[s.slot_of_tet[t] as usize].live)
    }

    /// The stress pass and the release check read the slots' live flags in mesh order:
    /// a release check switches tets off in both, the stress pass then skips them (zero
    /// stress) and takes the others, and reviving the pending releases switches them on
    /// in both again.
    #[test]
    fn the_tet_by_tet_passes_see_the_sweeps_live_flags() {
        let mut s = shaken();
        s.compute_stress();
        s.switch_off_overstressed();
        let off: Vec<usize> = (0..s.mesh.tet_count())
            .filter(|&t| !s.tet_live[t])
            .collect();
        assert!(
            !off.is_empty() && off.len() < s.mesh.tet_count() / 2,
            "{} of {} tets released",
            off.len(),
            s.mesh.tet_count()
        );
        assert!(flags_agree(&s), "after the release check");
        s.compute_stress();
        assert!(
            off.iter().all(|&t| s.von_mises[t] == 0.0),
            "a released tet's stress"
        );
        let taken = (0..s.mesh.tet_count()).filter(|&t| s.tet_live[t] && s.von_mises[t] > 0.0);
        assert!(
            taken.count() > s.mesh.tet_count() / 2,
            "the live tets' stress"
        );
        s.revive_pending();
        assert!(
            flags_agree(&s) && s.tet_live.iter().all(|&l| l),
            "after reviving"
        );
        assert_eq!(s.live_tets(), s.tet_live);
    }
}
