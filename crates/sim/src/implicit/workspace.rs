//! One implicit Euler step as a minimisation (PHYSICS.md §1.2's energy; the variational
//! form of implicit Euler, as in `vbd/solver.rs`):
//!
//! ```text
//! u_{n+1} = argmin G(u),   G(u) = 1/(2h²) ‖u − y‖²_M + Σ_t V_t Ψ(F_t(u)),   y = u_n + h v_n + h² g
//! ```
//!
//! over the free nodes (pinned and grabbed nodes hold their targets). Each Newton
//! iteration solves `∇²G d = −∇G` by [`pcg`] with the exact Hessian applied tet by tet
//! ([`TetTangent`]) and a two-level preconditioner: block Jacobi (each node's 3×3
//! diagonal block, as VBD's local system) plus a coarse-grid correction `P A_c⁻¹ Pᵀ`
//! ([`CoarseSystem`]). A backtracking line search on `G` keeps every step a descent.

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use super::coarse_assembly::CoarseAssembly;
use super::coarse_grid::CoarseGrid;
use super::coarse_system::{CoarseError, CoarseSystem};
use super::params::{CoarseRefresh, NewtonParams};
use super::pcg::{dot, pcg};
use super::product_lanes::{RestLanes, TangentLanes, product, rest_lanes, tangent_lanes};
use super::rest_tet::RestTet;
use super::tet_tangent::TetTangent;
use crate::material::Lame;
use crate::mesh::TetMesh;
use crate::vbd::{energy_density, piola, shape_gradients};
use crate::xpbd::lanes::LANES;
use crate::xpbd::{Strain, displacement_gradient};

/// Items per rayon task.
const CHUNK: usize = 256;
/// Armijo constant of the line search.
const ARMIJO: f64 = 1e-4;
/// Most halvings of a Newton step before the step is abandoned.
const MAX_HALVINGS: u32 = 8;

/// What the last implicit step cost.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NewtonReport {
    /// Newton iterations taken.
    pub iterations: u32,
    /// Hessian–vector products over all iterations.
    pub cg_products: u32,
    /// Iterations whose conjugate gradient met non-positive curvature.
    pub negative_curvature: u32,
    /// Step halvings of the line search.
    pub halvings: u32,
    /// `|∇G|` where the last iteration started (or where the gradient stop ended the step)
    /// over `|∇G|` at the step's first iterate (free nodes, 2-norm).
    pub gradient_ratio: f32,
    /// Whether the coarse matrix was re-assembled from the current tangents this step.
    pub coarse_refreshed: bool,
    /// Whether that refresh was not positive definite (the previous factor was kept).
    pub coarse_refresh_failed: bool,
}

/// One tet's evaluation at the current iterate.
#[derive(Debug, Clone, Copy)]
struct TetEval {
    forces: [Vec3; 4],
    diag: [Mat3; 4],
    tangent: TetTangent,
    energy: f32,
}

/// The Hessian of `G` applied matrix-free.
struct Hessian {
    tets: Vec<RestTet>,
    b: Vec<[Vec3; 4]>,
    inc_offsets: Vec<u32>,
    inc: Vec<(u32, u8)>,
    mass: Vec<f32>,
    inv_h2: f32,
    lame: Lame,
    evals: Vec<TetEval>,
    products: Vec<[Vec3; 4]>,
    /// The tets in chunks of eight for the SIMD product, with their tangents (`None`:
    /// the scalar product, the reference).
    lanes: Option<(Vec<RestLanes>, Vec<TangentLanes>)>,
}

/// Block Jacobi plus the coarse correction.
struct TwoLevel {
    diag_inv: Vec<Mat3>,
    grid: CoarseGrid,
    coarse: CoarseSystem,
    /// The tets' corner pairs for re-assembling `coarse` (`None` under
    /// [`CoarseRefresh::Rest`]).
    assembly: Option<CoarseAssembly>,
    /// The tangents of the last refresh, per tet (what a release subtracts).
    used: Vec<TetTangent>,
    /// Steps since the last refresh.
    since_refresh: u32,
    rhs: Vec<f64>,
}

/// Buffers and the preconditioner of the implicit scheme for one body.
pub struct NewtonWorkspace {
    params: NewtonParams,
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
    /// builds the coarse grid and factorises its matrix.
    pub fn new(
        mesh: &TetMesh,
        mass: &[f32],
        free: &[bool],
        lame: Lame,
        (h, lanes): (f32, bool),
        params: NewtonParams,
    ) -> Result<Self, CoarseError> {
        let tets = RestTet::all(mesh);
        let cell = params
            .coarse_cell
            .unwrap_or_else(|| 4.0 * mesh.mean_edge_length());
        let grid = CoarseGrid::new(&mesh.rest_positions, free, cell);
        let inv_h2 = 1.0 / (h * h);
        let coarse = CoarseSystem::new(&grid, &tets, mass, inv_h2, lame)?;
        let (inc_offsets, inc) = (mesh.node_tet_offsets.clone(), mesh.node_corners());
        let n = mesh.node_count();
        let rest = TetEval {
            forces: [Vec3::ZERO; 4],
            diag: [Mat3::ZERO; 4],
            tangent: rest_tangent(lame),
            energy: 0.0,
        };
        let b: Vec<[Vec3; 4]> = tets.iter().map(|t| shape_gradients(&t.dm_inv)).collect();
        let assembly = (params.coarse_refresh != CoarseRefresh::Rest)
            .then(|| CoarseAssembly::new(&grid, &tets, &b, coarse.block_index()));
        let lanes = lanes.then(|| {
            let rest = rest_lanes(&tets, &b);
            let tangents = vec![tangent_lanes(0, |_| rest_tangent(lame)); rest.len()];
            (rest, tangents)
        });
        Ok(NewtonWorkspace {
            params,
            hessian: Hessian {
                b,
                lanes,
                evals: vec![rest; tets.len()],
                products: vec![[Vec3::ZERO; 4]; tets.len()],
                tets,
                inc_offsets,
                inc,
                mass: mass.to_vec(),
                inv_h2,
                lame,
            },
            pre: TwoLevel {
                diag_inv: vec![Mat3::ZERO; n],
                rhs: vec![0.0; 3 * grid.count],
                grid,
                coarse,
                assembly,
                used: Vec::new(),
                since_refresh: 0,
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
        (self.pre.grid.count, self.pre.coarse.nonzeros())
    }

    /// Take released tets (mesh indices) out of the coarse matrix: their rest stiffness
    /// (before any refresh) or their blocks at the last refresh's tangents.
    pub fn release(&mut self, tets: &[u32]) -> Result<(), CoarseError> {
        let pre = &mut self.pre;
        if let (Some(assembly), false) = (&pre.assembly, pre.used.is_empty()) {
            return pre.coarse.release_refreshed(assembly, tets, &pre.used);
        }
        let gone: Vec<RestTet> = tets
            .iter()
            .map(|&t| self.hessian.tets[t as usize])
            .collect();
        self.pre
            .coarse
            .release(&self.pre.grid, &gone, self.hessian.lame)
    }

    /// Minimise `G` from `u` (which holds the initial guess, `y` at free nodes and the
    /// targets at fixed ones); `live` per tet (mesh order), `free` per node.
    pub fn solve(
        &mut self,
        u: &mut [Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        parallel: bool,
    ) {
        let mut report = NewtonReport::default();
        let mut g_now = self.hessian.evaluate(u, y, live, free, parallel);
        if self.refresh_due() {
            let evals = &self.hessian.evals;
            let tangent = |t: usize| live[t].then(|| &evals[t].tangent);
            let pre = &mut self.pre;
            let assembly = pre
                .assembly
                .as_mut()
                .expect("a refresh policy has an assembly");
            report.coarse_refreshed = true;
            report.coarse_refresh_failed = pre.coarse.refresh(assembly, tangent, parallel).is_err();
            // The blocks are these tangents' even where the factor stayed the old one.
            pre.used.clear();
            pre.used.extend(evals.iter().map(|e| e.tangent));
            pre.since_refresh = 0;
        }
        self.pre.since_refresh += 1;
        let mut first_norm = None;
        for _ in 0..self.params.iterations {
            self.hessian.gather_gradient(
                u,
                y,
                free,
                &mut self.gradient,
                &mut self.pre.diag_inv,
                parallel,
            );
            let norm = dot(&self.gradient, &self.gradient).sqrt();
            let first = *first_norm.get_or_insert(norm);
            report.gradient_ratio = if first > 0.0 {
                (norm / first) as f32
            } else {
                0.0
            };
            if norm == 0.0 || norm <= self.params.gradient_tolerance as f64 * first {
                break;
            }
            for (r, g) in self.rhs.iter_mut().zip(&self.gradient) {
                *r = -*g;
            }
            let (hessian, pre) = (&mut self.hessian, &mut self.pre);
            let cg = pcg(
                &self.rhs,
                &mut self.direction,
                self.params.cg_iterations,
                self.params.cg_tolerance,
                |p, out| hessian.apply(p, out, live, free, parallel),
                |r, z| pre.apply(r, z, free, parallel),
            );
            report.iterations += 1;
            report.cg_products += cg.iterations;
            report.negative_curvature += u32::from(cg.negative_curvature);
            let slope = dot(&self.gradient, &self.direction);
            if slope >= 0.0 {
                break;
            }
            match self.line_search(u, y, live, free, g_now, slope, parallel, &mut report) {
                Some(g) => g_now = g,
                None => break,
            }
        }
        self.last = report;
    }

    /// Whether this step re-assembles the coarse matrix (module docs, [`CoarseRefresh`]).
    fn refresh_due(&self) -> bool {
        let pre = &self.pre;
        if pre.assembly.is_none() {
            return false;
        }
        match self.params.coarse_refresh {
            CoarseRefresh::Rest => false,
            CoarseRefresh::Steps(n) => pre.since_refresh >= n,
            CoarseRefresh::Products(bound) => {
                self.last.cg_products > bound * self.last.iterations.max(1)
            }
        }
    }

    /// Backtrack along the direction from `u` until `G` decreases enough; on success `u`
    /// moves there and the tet evaluations are the new point's, else `u` stays and they
    /// are `u`'s again. Returns the new `G`. The full step is evaluated in full (it is
    /// usually taken); a halved one only for its energy, and in full once taken.
    #[allow(clippy::too_many_arguments)]
    fn line_search(
        &mut self,
        u: &mut [Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        g_now: f64,
        slope: f64,
        parallel: bool,
        report: &mut NewtonReport,
    ) -> Option<f64> {
        let mut alpha = 1.0f32;
        // f32 energies summed in f64: changes below this are rounding.
        let rounding = 1e-6 * g_now.abs();
        for halving in 0..=MAX_HALVINGS {
            for ((t, u), d) in self.trial.iter_mut().zip(u.iter()).zip(&self.direction) {
                *t = *u + alpha * *d;
            }
            let g_trial = if halving == 0 {
                self.hessian.evaluate(&self.trial, y, live, free, parallel)
            } else {
                self.hessian.energy(&self.trial, y, live, free, parallel)
            };
            if g_trial <= g_now + ARMIJO * alpha as f64 * slope + rounding {
                if halving > 0 {
                    self.hessian.evaluate(&self.trial, y, live, free, parallel);
                }
                u.copy_from_slice(&self.trial);
                return Some(g_trial);
            }
            alpha *= 0.5;
            report.halvings += 1;
        }
        self.hessian.evaluate(u, y, live, free, parallel);
        None
    }
}

impl Hessian {
    /// Forces, diagonal blocks, tangents and energy of every live tet at `u`; returns `G(u)`.
    fn evaluate(
        &mut self,
        u: &[Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        parallel: bool,
    ) -> f64 {
        let (tets, b, lame) = (&self.tets, &self.b, self.lame);
        let eval = |t: usize, out: &mut TetEval| {
            if !live[t] {
                out.energy = 0.0;
                out.forces = [Vec3::ZERO; 4];
                out.diag = [Mat3::ZERO; 4];
                return;
            }
            let tet = &tets[t];
            let s = tet.strain(u);
            let p = piola(&s, lame) * tet.volume;
            out.tangent = TetTangent::at(&s, lame);
            out.energy = tet.volume * energy_density(&s, lame);
            for (a, ba) in b[t].iter().enumerate() {
                out.forces[a] = p * *ba;
                out.diag[a] = out.tangent.diagonal_block(tet.volume, *ba);
            }
        };
        for_each(parallel, &mut self.evals, eval);
        if let Some((_, tangents)) = &mut self.lanes {
            let evals = &self.evals;
            for_each(parallel, tangents, |c, t| {
                let chunk = &evals[c * LANES..(c * LANES + LANES).min(evals.len())];
                *t = tangent_lanes(chunk.len(), |k| chunk[k].tangent);
            });
        }
        self.total(u, y, free)
    }

    /// `G(u)` alone: only the tets' energies are updated (their forces, diagonal blocks
    /// and tangents stay those of the last [`Hessian::evaluate`]); the same value
    /// `evaluate` returns, to the bit.
    fn energy(
        &mut self,
        u: &[Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        parallel: bool,
    ) -> f64 {
        let (tets, lame) = (&self.tets, self.lame);
        let eval = |t: usize, out: &mut TetEval| {
            out.energy = if live[t] {
                let tet = &tets[t];
                tet.volume * energy_density(&tet.strain(u), lame)
            } else {
                0.0
            };
        };
        for_each(parallel, &mut self.evals, eval);
        self.total(u, y, free)
    }

    /// `G` from the tets' energies and the inertia at `u`.
    fn total(&self, u: &[Vec3], y: &[Vec3], free: &[bool]) -> f64 {
        let elastic: f64 = self.evals.iter().map(|e| e.energy as f64).sum();
        let inertia: f64 = (0..u.len())
            .filter(|&i| free[i])
            .map(|i| (self.mass[i] * (u[i] - y[i]).length_squared()) as f64)
            .sum();
        elastic + 0.5 * self.inv_h2 as f64 * inertia
    }

    /// `∇G` and the inverted diagonal blocks of `∇²G` per node (zero at fixed nodes).
    fn gather_gradient(
        &self,
        u: &[Vec3],
        y: &[Vec3],
        free: &[bool],
        gradient: &mut [Vec3],
        diag_inv: &mut [Mat3],
        parallel: bool,
    ) {
        let node = |i: usize, out: (&mut Vec3, &mut Mat3)| {
            if !free[i] {
                *out.0 = Vec3::ZERO;
                *out.1 = Mat3::ZERO;
                return;
            }
            let m = self.mass[i] * self.inv_h2;
            let mut g = (u[i] - y[i]) * m;
            let mut d = Mat3::IDENTITY * m;
            for &(t, a) in self.incident(i) {
                let e = &self.evals[t as usize];
                g += e.forces[a as usize];
                d += e.diag[a as usize];
            }
            *out.0 = g;
            *out.1 = d.inverse();
        };
        if parallel {
            gradient
                .par_iter_mut()
                .zip(diag_inv.par_iter_mut())
                .enumerate()
                .with_min_len(CHUNK)
                .for_each(|(i, (g, d))| node(i, (g, d)));
        } else {
            for (i, (g, d)) in gradient.iter_mut().zip(diag_inv.iter_mut()).enumerate() {
                node(i, (g, d));
            }
        }
    }

    /// `out = ∇²G p` (zero at fixed nodes).
    fn apply(
        &mut self,
        p: &[Vec3],
        out: &mut [Vec3],
        live: &[bool],
        free: &[bool],
        parallel: bool,
    ) {
        if let Some((rest, tangents)) = &self.lanes {
            let run = |(c, out): (usize, &mut [[Vec3; 4]])| {
                let live = &live[c * LANES..(c * LANES + out.len())];
                product(&rest[c], &tangents[c], live, p, out);
            };
            if parallel {
                self.products
                    .par_chunks_mut(LANES)
                    .enumerate()
                    .with_min_len(CHUNK / LANES)
                    .for_each(run);
            } else {
                self.products.chunks_mut(LANES).enumerate().for_each(run);
            }
        } else {
            self.scalar_products(p, live, parallel);
        }
        self.gather_products(p, out, free, parallel);
    }

    /// The tet-by-tet product (the reference for the lanes).
    fn scalar_products(&mut self, p: &[Vec3], live: &[bool], parallel: bool) {
        let (tets, b, evals) = (&self.tets, &self.b, &self.evals);
        let product = |t: usize, f: &mut [Vec3; 4]| {
            if !live[t] {
                *f = [Vec3::ZERO; 4];
                return;
            }
            let tet = &tets[t];
            let dp = tet.nodes.map(|i| p[i as usize]);
            let df = displacement_gradient(&dp, &tet.dm_inv);
            let stress = evals[t].tangent.dp(&df) * tet.volume;
            for a in 0..4 {
                f[a] = stress * b[t][a];
            }
        };
        for_each(parallel, &mut self.products, product);
    }

    /// `out = M/h² p + Σ` the tets' forces at each free node (zero at fixed nodes).
    fn gather_products(&self, p: &[Vec3], out: &mut [Vec3], free: &[bool], parallel: bool) {
        let (products, mass, inv_h2) = (&self.products, &self.mass, self.inv_h2);
        let node = |i: usize, o: &mut Vec3| {
            if !free[i] {
                *o = Vec3::ZERO;
                return;
            }
            let mut sum = p[i] * (mass[i] * inv_h2);
            for &(t, a) in self.incident(i) {
                sum += products[t as usize][a as usize];
            }
            *o = sum;
        };
        for_each(parallel, out, node);
    }

    /// The (tet, corner) pairs of node `i`.
    fn incident(&self, i: usize) -> &[(u32, u8)] {
        &self.inc[self.inc_offsets[i] as usize..self.inc_offsets[i + 1] as usize]
    }
}

impl TwoLevel {
    /// `z = D⁻¹ r + P A_c⁻¹ Pᵀ r` (additive two-level; zero at fixed nodes).
    fn apply(&mut self, r: &[Vec3], z: &mut [Vec3], free: &[bool], parallel: bool) {
        for i in 0..r.len() {
            z[i] = self.diag_inv[i] * r[i];
        }
        self.grid.restrict(r, &mut self.rhs, parallel);
        self.coarse.solve(&mut self.rhs);
        self.grid.prolong_add(&self.rhs, z, parallel);
        for (z, f) in z.iter_mut().zip(free) {
            if !f {
                *z = Vec3::ZERO;
            }
        }
    }
}

/// The tangent at rest.
fn rest_tangent(lame: Lame) -> TetTangent {
    TetTangent::at(&Strain::of(Mat3::ZERO), lame)
}

/// `f(i, &mut out[i])` for every item, on the pool's threads when `parallel`.
fn for_each<T: Send>(parallel: bool, out: &mut [T], f: impl Fn(usize, &mut T) + Sync) {
    if parallel {
        out.par_iter_mut()
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, o)| f(i, o));
    } else {
        out.iter_mut().enumerate().for_each(|(i, o)| f(i, o));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::block;

    fn setup() -> (TetMesh, NewtonWorkspace, Vec<bool>) {
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
            (1.0 / 60.0, false),
            NewtonParams::default(),
        )
        .unwrap();
        (mesh, ws, free)
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
            )
            .unwrap()
        };
        let (mut scalar, mut lanes) = (make(false), make(true));
        let n = mesh.node_count();
        let live: Vec<bool> = (0..mesh.tet_count()).map(|t| t % 5 != 3).collect();
        let u = wobble(n, 1e-3);
        let p = wobble(n + 5, 1.0)[5..].to_vec();
        let mut out = [vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]];
        for (ws, o) in [&mut scalar, &mut lanes].into_iter().zip(out.iter_mut()) {
            ws.hessian.evaluate(&u, &u, &live, &free, true);
            ws.hessian.apply(&p, o, &live, &free, true);
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
            ws.hessian.evaluate(&x, &y, &live, &free, false);
            let mut g = vec![Vec3::ZERO; n];
            let mut d = vec![Mat3::ZERO; n];
            ws.hessian
                .gather_gradient(&x, &y, &free, &mut g, &mut d, false);
            g
        };
        let eps = 1e-6;
        let (gp, gm) = (grad_at(&mut ws, eps), grad_at(&mut ws, -eps));
        ws.hessian.evaluate(&u, &y, &live, &free, false);
        let mut hp = vec![Vec3::ZERO; n];
        ws.hessian.apply(&p, &mut hp, &live, &free, false);
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
}
