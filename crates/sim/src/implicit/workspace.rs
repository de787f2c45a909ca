//! One implicit Euler step as a minimisation (PHYSICS.md §1.2's energy; the variational
//! form of implicit Euler, as in `vbd/solver.rs`):
//!
//! ```text
//! u_{n+1} = argmin G(u),   G(u) = 1/(2h²) ‖u − y‖²_M + Σ_t V_t Ψ(F_t(u)),   y = u_n + h v_n + h² g
//! ```
//!
//! over the free nodes (pinned and grabbed nodes hold their targets). Each Newton
//! iteration solves `∇²G d = −∇G` by [`pcg`] with the exact Hessian applied tet by tet
//! ([`super::TetTangent`]) and a two-level preconditioner: block Jacobi (each node's 3×3
//! diagonal block, as VBD's local system) or, with `smoother: GaussSeidel`, a symmetric
//! block Gauss–Seidel sweep on the Hessian assembled at the step's first iterate
//! ([`BlockMatrix`]), plus a coarse-grid correction `P A_c⁻¹ Pᵀ` ([`super::CoarseLevel`]). A
//! backtracking line search on `G` keeps every step a descent.

use glam::{Mat3, Vec3};

use super::block_matrix::BlockMatrix;
use super::coarse_level::CoarseLevel;
use super::coarse_system::CoarseError;
use super::hessian::Hessian;
use super::newton_report::NewtonReport;
use super::params::{NewtonParams, Smoother};
use super::pcg::{dot, pcg};
use super::product_parts::ProductParts;
use super::rest_tet::RestTet;
use super::tet_evals::TetEvals;
use super::two_level::TwoLevel;
use crate::material::Lame;
use crate::mesh::TetMesh;
use crate::thread_team::ThreadTeam;
use crate::vbd::shape_gradients;

/// Armijo constant of the line search.
const ARMIJO: f64 = 1e-4;
/// Most halvings of a Newton step before the step is abandoned.
const MAX_HALVINGS: u32 = 8;

/// Buffers and the preconditioner of the implicit scheme for one body.
pub struct NewtonWorkspace {
    params: NewtonParams,
    /// The mesh's mean rest edge, m (the step stop's unit).
    mean_edge: f32,
    hessian: Hessian,
    pre: TwoLevel,
    gradient: Vec<Vec3>,
    rhs: Vec<Vec3>,
    direction: Vec<Vec3>,
    trial: Vec<Vec3>,
    /// The last step's cost.
    pub last: NewtonReport,
}

impl NewtonWorkspace {
    /// The workspace for `mesh` with lumped `mass`, the nodes marked `free` solved for,
    /// step length `h`, the Hessian product in SIMD lanes or (`lanes` false) tet by tet:
    /// builds the coarse grid and factorises its matrix (assembled on `team`'s threads).
    pub fn new(
        mesh: &TetMesh,
        mass: &[f32],
        free: &[bool],
        lame: Lame,
        (h, lanes): (f32, bool),
        params: NewtonParams,
        team: Option<&ThreadTeam>,
    ) -> Result<Self, CoarseError> {
        let tets = RestTet::all(mesh);
        let inv_h2 = 1.0 / (h * h);
        let (inc_offsets, inc) = (mesh.node_tet_offsets.clone(), mesh.node_corners());
        let n = mesh.node_count();
        let b: Vec<[Vec3; 4]> = tets.iter().map(|t| shape_gradients(&t.dm_inv)).collect();
        let level = CoarseLevel::new(mesh, (&tets, &b), (mass, free), (lame, h), &params, team)?;
        let evals = TetEvals::at_rest(&tets, lame, lanes);
        let matrix = (params.smoother == Smoother::GaussSeidel).then(|| BlockMatrix::new(n, &tets));
        Ok(NewtonWorkspace {
            params,
            mean_edge: mesh.mean_edge_length(),
            hessian: Hessian {
                b,
                evals,
                product_parts: ProductParts::default(),
                active: Vec::new(),
                fixed: Vec::new(),
                tets,
                inc_offsets,
                inc,
                mass: mass.to_vec(),
                inv_h2,
                lame,
            },
            pre: TwoLevel {
                diag_inv: vec![Mat3::ZERO; n],
                rhs: vec![0.0; 3 * level.grid.count],
                coarse: Vec::new(),
                level,
                matrix,
            },
            gradient: vec![Vec3::ZERO; n],
            rhs: vec![Vec3::ZERO; n],
            direction: vec![Vec3::ZERO; n],
            trial: vec![Vec3::ZERO; n],
            last: NewtonReport::default(),
        })
    }

    /// Coarse nodes and the nonzeros of the coarse matrix's lower triangle.
    pub fn coarse_size(&self) -> (usize, usize) {
        let level = &self.pre.level;
        (level.grid.count, level.system.nonzeros())
    }

    /// Take released tets (mesh indices) out of the coarse matrix
    /// ([`CoarseLevel::release`]; refactorised by the next step or
    /// [`NewtonWorkspace::settle_coarse`]).
    pub fn release(&mut self, tets: &[u32]) {
        self.pre.level.release(tets);
    }

    /// Refactorise the coarse matrix after releases now, unless the coming step
    /// re-assembles it anyway (the step does it first otherwise, to the same bits): what
    /// a caller does between showing a frame and taking the next one's tool pose
    /// (`Solver::prepare_frame`). Whether there was one to do.
    pub fn settle_coarse(&mut self) -> bool {
        self.pre.level.settle_ahead(&self.last)
    }

    /// Solve the next steps at step length `h` (a frame run again at more steps under
    /// the blade, docs/physics-notes.md "The implicit scheme under a blade"): the inertia
    /// term changes; the coarse level keeps the scene's own step's (it only
    /// preconditions), as on the device.
    pub fn set_step_length(&mut self, h: f32) {
        self.hessian.inv_h2 = 1.0 / (h * h);
    }

    /// Minimise `G` from `u` (which holds the initial guess, `y` at free nodes and the
    /// targets at fixed ones); `live` per tet (mesh order), `free` per node.
    pub fn solve(
        &mut self,
        u: &mut [Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        team: Option<&ThreadTeam>,
    ) {
        let mut report = NewtonReport::default();
        // The step's first evaluation covers every tet; the later ones skip the chunks
        // whose tets reach no free node (their nodes hold their targets all step).
        self.hessian.fixed.clear();
        let mut g_now = self.hessian.evaluate(u, y, live, free, team);
        self.hessian.find_active(live, free);
        if self.pre.level.refresh_due(&self.last) {
            report.coarse_refreshed = true;
            report.coarse_refresh_failed = self.refresh_coarse(live, team).is_err();
        } else {
            // After releases (a refresh refactorises anyway); the previous factor stays
            // where this fails.
            let _ = self.pre.level.settle();
        }
        self.pre.level.tick();
        if let Some(m) = &mut self.pre.matrix {
            let h = &self.hessian;
            let mass = |i: usize| h.mass[i] * h.inv_h2;
            m.assemble((&h.tets, &h.b), (&h.evals, live), mass, true, team);
        }
        let mut first_norm = None;
        for _ in 0..self.params.iterations {
            self.hessian.gather_gradient(
                u,
                y,
                free,
                &mut self.gradient,
                &mut self.pre.diag_inv,
                team,
            );
            let norm = dot(&self.gradient, &self.gradient).sqrt();
            let stop;
            (report.gradient_ratio, stop) = self.params.gradient_stop(&mut first_norm, norm);
            if stop {
                break;
            }
            for (r, g) in self.rhs.iter_mut().zip(&self.gradient) {
                *r = -*g;
            }
            let (hessian, pre) = (&mut self.hessian, &mut self.pre);
            let mut solve = |smooth: bool| {
                pcg(
                    &self.rhs,
                    &mut self.direction,
                    self.params.cg_iterations,
                    self.params.cg_tolerance,
                    |p, out| hessian.apply(p, out, live, free, team),
                    |r, z| pre.apply(r, z, free, team, smooth),
                )
            };
            let mut cg = solve(true);
            if cg.negative_curvature
                && cg.iterations == 1
                && self.params.smoother != Smoother::Jacobi
            {
                // The Gauss–Seidel direction leads into the Hessian's indefinite part
                // (after a tear): solve this iteration with block Jacobi.
                report.cg_products += 1;
                cg = solve(false);
            }
            report.iterations += 1;
            report.cg_products += cg.iterations;
            report.negative_curvature += u32::from(cg.negative_curvature);
            let slope = dot(&self.gradient, &self.direction);
            if slope >= 0.0 {
                break;
            }
            let first = FirstTrial::after(cg.negative_curvature);
            match self.line_search(u, y, (live, free), (g_now, slope), first, team, &mut report) {
                Some((g, alpha)) => {
                    g_now = g;
                    let moved = alpha * reach(&self.direction, free);
                    if self.params.step_stop(moved, self.mean_edge) {
                        break;
                    }
                }
                None => break,
            }
        }
        report.coarse_nodes = self.pre.level.grid.count as u32;
        self.last = report;
    }

    /// `∂G/∂x` at `node` with the tet evaluations of the last iterate, `m/h² (u − y)` plus
    /// the corner forces of its tets: after [`NewtonWorkspace::solve`] held the node fixed,
    /// the force whatever held it (the tool's blade) pushes it with, N.
    pub fn reaction(&self, u: &[Vec3], y: &[Vec3], node: usize) -> Vec3 {
        self.hessian.node_sums(u, y, node).0
    }

    /// Tet `t`'s share of [`NewtonWorkspace::reaction`] at its corner `a` (its elastic
    /// energy's gradient there at the last iterate), N.
    pub fn corner_reaction(&self, t: usize, a: usize) -> Vec3 {
        self.hessian.evals.force(t, a)
    }

    /// Re-assemble the coarse matrix from the live tets' current tangents and refactorise
    /// it (the previous factor stays where the new one fails).
    fn refresh_coarse(
        &mut self,
        live: &[bool],
        team: Option<&ThreadTeam>,
    ) -> Result<(), CoarseError> {
        let evals = &self.hessian.evals;
        let done = self.pre.level.refresh(|t| evals.tangent(t), live, team);
        self.pre.rhs.resize(3 * self.pre.level.grid.count, 0.0);
        done
    }

    /// Backtrack along the direction from `u` (`G` and its slope there) until `G`
    /// decreases enough; on success `u` moves there and the tet evaluations are the new
    /// point's, else `u` stays and they are `u`'s again. Returns the new `G` and the
    /// step's length along the direction (`α`). The full step is evaluated as `first`
    /// says, a halved one for its energy only; a point evaluated for its energy alone is
    /// evaluated in full once taken.
    #[allow(clippy::too_many_arguments)]
    fn line_search(
        &mut self,
        u: &mut [Vec3],
        y: &[Vec3],
        (live, free): (&[bool], &[bool]),
        (g_now, slope): (f64, f64),
        first: FirstTrial,
        team: Option<&ThreadTeam>,
        report: &mut NewtonReport,
    ) -> Option<(f64, f32)> {
        let mut alpha = 1.0f32;
        // f32 energies summed in f64: changes below this are rounding.
        let rounding = 1e-6 * g_now.abs();
        for halving in 0..=MAX_HALVINGS {
            for ((t, u), d) in self.trial.iter_mut().zip(u.iter()).zip(&self.direction) {
                *t = *u + alpha * *d;
            }
            let full = halving == 0 && first == FirstTrial::Full;
            let g_trial = if full {
                self.hessian.evaluate(&self.trial, y, live, free, team)
            } else {
                self.hessian.energy(&self.trial, y, live, free, team)
            };
            if g_trial <= g_now + ARMIJO * alpha as f64 * slope + rounding {
                if !full {
                    self.hessian.evaluate(&self.trial, y, live, free, team);
                }
                u.copy_from_slice(&self.trial);
                return Some((g_trial, alpha));
            }
            alpha *= 0.5;
            report.halvings += 1;
        }
        self.hessian.evaluate(u, y, live, free, team);
        None
    }
}

/// How the line search evaluates the full step: in full where it is usually taken, for
/// its energy alone where it is usually halved. Either way the same point is taken and
/// its evaluation is the same to the bit (an energy alone is the full evaluation's); only
/// the work differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FirstTrial {
    /// Forces, blocks, tangents and energy at once.
    Full,
    /// The energy first; the rest once the step is taken.
    EnergyFirst,
}

impl FirstTrial {
    /// After a conjugate gradient that stopped at non-positive curvature (`negative`),
    /// the full step is halved more often than not (on the default organ after its tear,
    /// 54 of 87 such steps against 8 of 299 others): its energy first.
    pub(crate) fn after(negative: bool) -> FirstTrial {
        if negative {
            FirstTrial::EnergyFirst
        } else {
            FirstTrial::Full
        }
    }
}

/// The furthest a free node moves along `d`, m.
fn reach(d: &[Vec3], free: &[bool]) -> f32 {
    d.iter()
        .zip(free)
        .filter(|(_, f)| **f)
        .map(|(d, _)| d.length_squared())
        .fold(0.0, f32::max)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::block;
    use crate::xpbd::lanes::LANES;

    fn setup() -> (TetMesh, NewtonWorkspace, Vec<bool>) {
        setup_with(false)
    }

    /// A 4 × 2 × 1 cm block pinned at x = 0, its product tet by tet or (`lanes`) in lanes.
    fn setup_with(lanes: bool) -> (TetMesh, NewtonWorkspace, Vec<bool>) {
        let raw = block(
            Vec3::ZERO,
            Vec3::new(0.04, 0.02, 0.01),
            glam::UVec3::new(8, 4, 2),
        );
        let mesh = TetMesh::from_raw(raw).unwrap().0;
        let free: Vec<bool> = mesh.rest_positions.iter().map(|p| p.x > 1e-4).collect();
        let lame = Lame {
            mu: 6.2e4,
            lambda: 5.59e5,
        };
        let mass = mesh.lumped_masses(1040.0);
        let ws = NewtonWorkspace::new(
            &mesh,
            &mass,
            &free,
            lame,
            (1.0 / 60.0, lanes),
            NewtonParams::default(),
            None,
        )
        .unwrap();
        (mesh, ws, free)
    }

    /// A 3.5 × 1.5 × 1 cm block pinned at x = 0 whose tet count is not a multiple of
    /// eight, with the scalar kernels and with the lanes.
    fn odd_blocks() -> (TetMesh, [NewtonWorkspace; 2], Vec<bool>) {
        let raw = block(
            Vec3::ZERO,
            Vec3::new(0.035, 0.015, 0.01),
            glam::UVec3::new(7, 3, 2),
        );
        let mesh = TetMesh::from_raw(raw).unwrap().0;
        assert_ne!(mesh.tet_count() % LANES, 0);
        let free: Vec<bool> = mesh.rest_positions.iter().map(|p| p.x > 1e-4).collect();
        let lame = Lame {
            mu: 6.2e4,
            lambda: 5.59e5,
        };
        let mass = mesh.lumped_masses(1040.0);
        let make = |lanes| {
            NewtonWorkspace::new(
                &mesh,
                &mass,
                &free,
                lame,
                (1.0 / 60.0, lanes),
                NewtonParams::default(),
                None,
            )
            .unwrap()
        };
        let pair = [make(false), make(true)];
        (mesh, pair, free)
    }

    fn wobble(n: usize, scale: f32) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let f = i as f32;
                Vec3::new((f * 0.7).sin(), (f * 1.3).cos(), (f * 0.4).sin()) * scale
            })
            .collect()
    }

    /// The SIMD product equals the tet-by-tet one to rounding, on a mesh whose tet count
    /// is not a multiple of eight and with some tets released.
    #[test]
    fn the_lanes_product_is_the_scalar_product() {
        let (mesh, [mut scalar, mut lanes], free) = odd_blocks();
        let team = ThreadTeam::new(2).unwrap();
        let n = mesh.node_count();
        let live: Vec<bool> = (0..mesh.tet_count()).map(|t| t % 5 != 3).collect();
        let u = wobble(n, 1e-3);
        let p = wobble(n + 5, 1.0)[5..].to_vec();
        let mut out = [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]];
        for (ws, o) in [&mut scalar, &mut lanes].into_iter().zip(out.iter_mut()) {
            ws.hessian.evaluate(&u, &u, &live, &free, Some(&team));
            ws.hessian.find_active(&live, &free);
            ws.hessian.apply(&p, o, &live, &free, Some(&team));
        }
        let scale = out[0].iter().map(|v| v.length()).fold(0.0, f32::max);
        let err = out[0]
            .iter()
            .zip(&out[1])
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        assert!(
            scale > 0.0 && err <= 1e-5 * scale,
            "lanes off by {err} of {scale}"
        );
    }

    /// The SIMD evaluation gives the scalar one's `G`, gradient, diagonal blocks and
    /// tangents up to rounding, with tets stretched, squashed below `J_MIN` and inverted,
    /// some released, and a tet count that is not a multiple of eight; the energy alone
    /// is the evaluation's to the bit.
    #[test]
    fn the_lanes_evaluation_is_the_scalar_evaluation() {
        let (mesh, [mut scalar, mut lanes], free) = odd_blocks();
        let team = ThreadTeam::new(2).unwrap();
        let n = mesh.node_count();
        let live: Vec<bool> = (0..mesh.tet_count()).map(|t| t % 5 != 3).collect();
        // Up to 4 mm on 5 mm cells: some tets flattened past J_MIN or inverted.
        let u = wobble(n, 4e-3);
        let y = wobble(n + 2, 1e-3)[2..].to_vec();
        let j_min = crate::xpbd::J_MIN;
        let squashed = (0..mesh.tet_count())
            .filter(|&t| live[t] && RestTet::all(&mesh)[t].strain(&u).j() < j_min)
            .count();
        assert!(squashed > 0, "no tet below J_MIN");
        let mut out = Vec::new();
        for ws in [&mut scalar, &mut lanes] {
            let g = ws.hessian.evaluate(&u, &y, &live, &free, Some(&team));
            let e = ws.hessian.energy(&u, &y, &live, &free, Some(&team));
            assert_eq!(
                g.to_bits(),
                e.to_bits(),
                "the energy alone is not the evaluation's"
            );
            let (mut grad, mut d) = (vec![Vec3::ZERO; n], vec![Mat3::ZERO; n]);
            ws.hessian
                .gather_gradient(&u, &y, &free, &mut grad, &mut d, Some(&team));
            let tangents: Vec<Mat3> = (0..mesh.tet_count())
                .filter(|&t| live[t])
                .map(|t| {
                    ws.hessian
                        .evals
                        .tangent(t)
                        .dp(&Mat3::from_diagonal(Vec3::ONE))
                })
                .collect();
            out.push((g, grad, d, tangents));
        }
        let (a, b) = (&out[0], &out[1]);
        assert!(
            (a.0 - b.0).abs() <= 1e-5 * a.0.abs(),
            "G {} vs {}",
            a.0,
            b.0
        );
        let worst = |x: &[Vec3], y: &[Vec3]| {
            let scale = x.iter().map(|v| v.length()).fold(0.0, f32::max);
            let err = x
                .iter()
                .zip(y)
                .map(|(p, q)| (*p - *q).length())
                .fold(0.0, f32::max);
            (err, scale)
        };
        let (err, scale) = worst(&a.1, &b.1);
        assert!(
            scale > 0.0 && err <= 1e-4 * scale,
            "gradient off by {err} of {scale}"
        );
        let cols = |m: &[Mat3]| -> Vec<Vec3> {
            m.iter()
                .flat_map(|m| [m.x_axis, m.y_axis, m.z_axis])
                .collect()
        };
        // The blocks are compared inverted (as the preconditioner holds them), which
        // multiplies their rounding by their condition number.
        let (err, scale) = worst(&cols(&a.2), &cols(&b.2));
        assert!(
            scale > 0.0 && err <= 1e-3 * scale,
            "blocks off by {err} of {scale}"
        );
        let (err, scale) = worst(&cols(&a.3), &cols(&b.3));
        assert!(
            scale > 0.0 && err <= 1e-4 * scale,
            "tangents off by {err} of {scale}"
        );
    }

    /// The assembled Hessian's product is the matrix-free one, on a deformed block with
    /// some tets released, assembled tet by tet and in lanes; and the definite form
    /// assembles alike both ways on a block crushed past `J_MIN`.
    #[test]
    fn the_assembled_hessian_is_the_matrix_free_one() {
        let mut definite = Vec::new();
        for lanes in [false, true] {
            let (mesh, mut ws, free) = setup_with(lanes);
            let n = mesh.node_count();
            let live: Vec<bool> = (0..mesh.tet_count()).map(|t| t % 7 != 2).collect();
            // CG's directions vanish at fixed nodes.
            let p: Vec<Vec3> = wobble(n + 5, 1.0)[5..]
                .iter()
                .zip(&free)
                .map(|(w, f)| if *f { *w } else { Vec3::ZERO })
                .collect();
            let mut assembled = |u: &[Vec3], exact: bool| {
                ws.hessian.evaluate(u, u, &live, &free, None);
                let mut want = vec![Vec3::ZERO; n];
                ws.hessian.find_active(&live, &free);
                ws.hessian.apply(&p, &mut want, &live, &free, None);
                let h = &ws.hessian;
                let mut m = BlockMatrix::new(n, &h.tets);
                let mass = |i: usize| h.mass[i] * h.inv_h2;
                m.assemble((&h.tets, &h.b), (&h.evals, &live), mass, !exact, None);
                let mut got = vec![Vec3::ZERO; n];
                m.mul(&p, &mut got, &free);
                (want, got)
            };
            let (want, got) = assembled(&wobble(n, 1e-3), true);
            let (err, scale) = worst(&want, &got);
            assert!(
                scale > 0.0 && err <= 1e-5 * scale,
                "lanes {lanes}: assembled off by {err} of {scale}"
            );
            definite.push(assembled(&wobble(n, 4e-3), false).1);
        }
        let (err, scale) = worst(&definite[0], &definite[1]);
        assert!(
            scale > 0.0 && err <= 1e-4 * scale,
            "definite, lanes against tet by tet: off by {err} of {scale}"
        );
    }

    /// The lanes' block whose only free nodes are one lone node (corner 2 of tet 40) and
    /// the far quarter, so that whole chunks of tets have no free node; every seventh tet
    /// released.
    fn mostly_fixed() -> (TetMesh, NewtonWorkspace, Vec<bool>, Vec<bool>) {
        let (mesh, ws, _) = setup_with(true);
        let lone = mesh.tets[40][2] as usize;
        let free = (0..mesh.node_count())
            .map(|i| i == lone || mesh.rest_positions[i].x > 0.0301)
            .collect();
        let live = (0..mesh.tet_count()).map(|t| t % 7 != 2).collect();
        (mesh, ws, free, live)
    }

    /// The product over the chunks with a free node is the product over every chunk, on
    /// [`mostly_fixed`]: whole chunks are skipped, and the lone node is each of its tets'
    /// corners in turn.
    #[test]
    fn the_product_skips_only_tets_without_a_free_node() {
        let (mesh, mut ws, free, live) = mostly_fixed();
        let n = mesh.node_count();
        let u = wobble(n, 1e-3);
        let p = wobble(n + 5, 1.0)[5..].to_vec();
        ws.hessian.evaluate(&u, &u, &live, &free, None);
        let chunks = mesh.tet_count().div_ceil(LANES);
        let mut out = [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]];
        ws.hessian.find_active(&live, &free);
        let skipped = chunks - ws.hessian.active.len();
        ws.hessian.apply(&p, &mut out[0], &live, &free, None);
        ws.hessian.active = (0..chunks as u32).collect();
        ws.hessian.apply(&p, &mut out[1], &live, &free, None);
        assert!(
            skipped > chunks / 4,
            "only {skipped} of {chunks} chunks skipped"
        );
        let (err, scale) = worst(&out[1], &out[0]);
        assert!(
            scale > 0.0 && err <= 1e-5 * scale,
            "the skipped chunks held a free node's forces: off by {err} of {scale}"
        );
    }

    /// Within a step the evaluations skip the chunks whose tets reach no free node and
    /// give the same `G` and gradient, to the bit, as evaluating every tet: those tets'
    /// nodes do not move.
    #[test]
    fn skipping_the_fixed_chunks_changes_no_bit_of_g() {
        let (mesh, mut ws, free, live) = mostly_fixed();
        let n = mesh.node_count();
        let start = wobble(n, 1e-3);
        let moved: Vec<Vec3> = start
            .iter()
            .zip(wobble(n + 9, 2e-4)[9..].iter().zip(&free))
            .map(|(u, (d, f))| if *f { *u + *d } else { *u })
            .collect();
        let y = wobble(n + 4, 1e-3)[4..].to_vec();
        let at_moved = |ws: &mut NewtonWorkspace| {
            let g = ws.hessian.evaluate(&moved, &y, &live, &free, None);
            let e = ws.hessian.energy(&moved, &y, &live, &free, None);
            let (mut grad, mut d) = (vec![Vec3::ZERO; n], vec![Mat3::ZERO; n]);
            ws.hessian
                .gather_gradient(&moved, &y, &free, &mut grad, &mut d, None);
            (g.to_bits(), e.to_bits(), grad)
        };
        ws.hessian.fixed.clear();
        ws.hessian.evaluate(&start, &y, &live, &free, None);
        ws.hessian.find_active(&live, &free);
        assert!(
            ws.hessian.fixed.iter().filter(|f| **f).count() > 4,
            "nothing skipped"
        );
        let skipping = at_moved(&mut ws);
        ws.hessian.fixed.clear();
        let whole = at_moved(&mut ws);
        assert_eq!(skipping.0, whole.0, "G differs");
        assert_eq!(skipping.1, whole.1, "the energy alone differs");
        assert!(skipping.2 == whole.2, "the gradient differs");
    }

    /// The largest difference of `a` and `b` and the largest length in `a`.
    fn worst(a: &[Vec3], b: &[Vec3]) -> (f32, f32) {
        let scale = a.iter().map(|v| v.length()).fold(0.0, f32::max);
        let err = a
            .iter()
            .zip(b)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f32::max);
        (err, scale)
    }

    /// A tet released by a check earlier in the frame and left out of a refresh since is
    /// not subtracted from the coarse matrix a second time when the frame hands its
    /// releases over: the matrix is then the refresh of the live tets.
    #[test]
    fn a_release_after_a_refresh_without_the_tet_subtracts_nothing() {
        let (mesh, mut fresh, free) = setup();
        let (_, mut released, _) = setup();
        let n = mesh.node_count();
        let u = wobble(n, 1e-5);
        let mut live = vec![true; mesh.tet_count()];
        live[5] = false;
        let rhs: Vec<f64> = (0..fresh.pre.rhs.len())
            .map(|i| (i as f64 * 0.37).sin())
            .collect();
        let mut solved = Vec::new();
        for ws in [&mut fresh, &mut released] {
            ws.hessian.evaluate(&u, &u, &live, &free, None);
            ws.refresh_coarse(&live, None).unwrap();
        }
        released.release(&[5]);
        released.pre.level.settle().unwrap();
        for ws in [&fresh, &released] {
            let mut x = rhs.clone();
            ws.pre.level.system.solve(&mut x);
            solved.push(x);
        }
        let scale = solved[0].iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let err = solved[0]
            .iter()
            .zip(&solved[1])
            .fold(0.0f64, |a, (p, q)| a.max((p - q).abs()));
        assert!(
            scale > 0.0 && err <= 1e-9 * scale,
            "the released tet was subtracted again: off by {err} of {scale}"
        );
    }

    /// A tet released before any refresh leaves the coarse matrix a refresh at rest of
    /// the live tets would give: its rest blocks come out.
    #[test]
    fn a_release_before_any_refresh_takes_out_the_rest_stiffness() {
        let (mesh, mut refreshed, free) = setup();
        let (_, mut released, _) = setup();
        let rest = vec![Vec3::ZERO; mesh.node_count()];
        let mut live = vec![true; mesh.tet_count()];
        live[5] = false;
        live[40] = false;
        refreshed.hessian.evaluate(&rest, &rest, &live, &free, None);
        refreshed.refresh_coarse(&live, None).unwrap();
        released.release(&[5, 40]);
        released.pre.level.settle().unwrap();
        let rhs: Vec<f64> = (0..released.pre.rhs.len())
            .map(|i| (i as f64 * 0.37).sin())
            .collect();
        let solved: Vec<Vec<f64>> = [&refreshed, &released]
            .map(|ws| {
                let mut x = rhs.clone();
                ws.pre.level.system.solve(&mut x);
                x
            })
            .into();
        let (err, scale) = solved[0]
            .iter()
            .zip(&solved[1])
            .fold((0.0f64, 0.0f64), |(e, s), (p, q)| {
                (e.max((p - q).abs()), s.max(p.abs()))
            });
        assert!(
            scale > 0.0 && err <= 1e-6 * scale,
            "the release left the coarse matrix off by {err} of {scale}"
        );
    }

    /// `∇²G p` against central differences of `∇G`, and positive curvature near rest.
    #[test]
    fn the_hessian_product_is_the_derivative_of_the_gradient() {
        let (mesh, mut ws, free) = setup();
        let n = mesh.node_count();
        let live = vec![true; mesh.tet_count()];
        let u: Vec<Vec3> = wobble(n, 2e-4)
            .into_iter()
            .zip(&free)
            .map(|(w, f)| if *f { w } else { Vec3::ZERO })
            .collect();
        let y = u.clone();
        let p: Vec<Vec3> = wobble(n + 3, 1.0)[3..]
            .iter()
            .zip(&free)
            .map(|(w, f)| if *f { *w } else { Vec3::ZERO })
            .collect();
        let grad_at = |ws: &mut NewtonWorkspace, s: f32| {
            let x: Vec<Vec3> = u.iter().zip(&p).map(|(u, p)| *u + s * *p).collect();
            ws.hessian.evaluate(&x, &y, &live, &free, None);
            let mut g = vec![Vec3::ZERO; n];
            let mut d = vec![Mat3::ZERO; n];
            ws.hessian
                .gather_gradient(&x, &y, &free, &mut g, &mut d, None);
            g
        };
        let eps = 1e-6;
        let (gp, gm) = (grad_at(&mut ws, eps), grad_at(&mut ws, -eps));
        ws.hessian.evaluate(&u, &y, &live, &free, None);
        let mut hp = vec![Vec3::ZERO; n];
        ws.hessian.find_active(&live, &free);
        ws.hessian.apply(&p, &mut hp, &live, &free, None);
        let fd: Vec<Vec3> = gp
            .iter()
            .zip(&gm)
            .map(|(a, b)| (*a - *b) / (2.0 * eps))
            .collect();
        let err = hp
            .iter()
            .zip(&fd)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        let scale = fd.iter().map(|v| v.length()).fold(0.0, f32::max);
        assert!(err < 0.02 * scale, "Hp off by {err} of {scale}");
        assert!(dot(&p, &hp) > 0.0);
    }

    /// The state a line search leaves: where it went, `G` and `α`, the halvings, and the
    /// gradient, inverted diagonal blocks and Hessian product the evaluations there give.
    type Searched = (
        Vec<Vec3>,
        Option<(f64, f32)>,
        u32,
        Vec<Vec3>,
        Vec<Mat3>,
        Vec<Vec3>,
    );

    /// One line search from `u` along `scale ×` the steepest descent, the full step
    /// evaluated as `first` says, on a team of two.
    fn search(u: &[Vec3], scale: f32, first: FirstTrial) -> Searched {
        let (mesh, mut ws, free) = setup_with(true);
        let team = ThreadTeam::new(2).unwrap();
        let (n, live) = (mesh.node_count(), vec![true; mesh.tet_count()]);
        let y = wobble(n + 3, 2e-4)[3..].to_vec();
        let mut u = u.to_vec();
        let g_now = ws.hessian.evaluate(&u, &y, &live, &free, Some(&team));
        ws.hessian.find_active(&live, &free);
        let (mut g, mut d) = (vec![Vec3::ZERO; n], vec![Mat3::ZERO; n]);
        ws.hessian
            .gather_gradient(&u, &y, &free, &mut g, &mut d, Some(&team));
        ws.direction = g.iter().map(|g| -scale * *g).collect();
        let slope = dot(&g, &ws.direction);
        let mut report = NewtonReport::default();
        let bounds = (&live[..], &free[..]);
        let taken = ws.line_search(
            &mut u,
            &y,
            bounds,
            (g_now, slope),
            first,
            Some(&team),
            &mut report,
        );
        ws.hessian
            .gather_gradient(&u, &y, &free, &mut g, &mut d, Some(&team));
        let mut hp = vec![Vec3::ZERO; n];
        let p = wobble(n + 7, 1e-3)[7..].to_vec();
        ws.hessian.apply(&p, &mut hp, &live, &free, Some(&team));
        (u, taken, report.halvings, g, d, hp)
    }

    /// Evaluating the full step for its energy first changes only the work: a step taken
    /// whole and one halved end at the same point with the same `G`, `α` and evaluations
    /// there (gradient, diagonal blocks, the product's tangents), to the bit.
    #[test]
    fn the_energy_first_takes_the_same_step_as_the_full_evaluation() {
        let (mesh, _, free) = setup_with(true);
        let u: Vec<Vec3> = wobble(mesh.node_count(), 5e-4)
            .iter()
            .zip(&free)
            .map(|(w, &f)| if f { *w } else { Vec3::ZERO })
            .collect();
        // A short step is taken whole; a long one is halved (more than once).
        for (scale, halved) in [(1e-7, false), (1e-3, true)] {
            let full = search(&u, scale, FirstTrial::Full);
            let energy_first = search(&u, scale, FirstTrial::EnergyFirst);
            assert!(full.1.is_some(), "scale {scale}: no step taken");
            assert_eq!(full.2 > 0, halved, "scale {scale}: {} halvings", full.2);
            assert!(full == energy_first, "scale {scale}: the searches differ");
        }
    }
}
