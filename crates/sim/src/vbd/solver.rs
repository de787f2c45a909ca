//! The VBD solver (Chen et al. 2024): each substep is one implicit-Euler step,
//! `x^{t+1} = argmin_x G(x)`, `G(x) = 1/(2h²) ‖x − y‖²_M + E(x)`, `y = xᵗ + h vᵗ + h² g`
//! (their §3.1, the variational form of implicit Euler), solved by Gauss–Seidel over
//! vertex blocks: for each vertex `i`, one Newton step on `G` in `x_i` alone with the
//! other vertices held (§3.2):
//!
//! ```text
//! f_i = −m_i/h² (x_i − y_i) − Σ_j ∂E_j/∂x_i
//! H_i =  m_i/h² I          + Σ_j ∂²E_j/∂x_i²        (PSD blocks, see energy.rs)
//! x_i ← x_i + H_i⁻¹ f_i
//! ```
//!
//! vertices of one colour in parallel (§3.4). Optional Rayleigh damping (§3.5),
//! initial guess (§3.7), Chebyshev acceleration (§3.8). The state is the displacement
//! `u = x − X`, as in the XPBD solver, so rest is exactly force-free in f32.
//! The equations are restated here; the § numbers refer to arXiv:2403.06321 as recalled
//! (the paper's text was not at hand to check them or its equation numbers).

use std::time::Instant;

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use super::chebyshev::chebyshev_omega;
use super::coloring::greedy_vertex_colors;
use super::energy::{energy_density, shape_gradients, vertex_gradient_hessian};
use super::params::{InitialGuess, VbdError, VbdParams};
use crate::grab::Grab;
use crate::material::{Lame, Material};
use crate::mesh::TetMesh;
use crate::stress::{cauchy_stress, von_mises};
use crate::xpbd::{ConstraintPair, NodeKind, Strain, displacement_gradient};

/// Nodes per rayon task.
const CHUNK: usize = 64;

/// Per-tet data one local solve reads.
#[derive(Debug, Clone, Copy)]
struct TetData {
    nodes: [u32; 4],
    dm_inv: Mat3,
    volume: f32,
    b: [Vec3; 4],
}

/// What one frame cost.
#[derive(Debug, Clone, Copy, Default)]
pub struct VbdFrameStats {
    /// Wall time of the frame's substeps, ms.
    pub solve_ms: f64,
}

/// Read-only inputs of one vertex's local solve.
struct Local<'a> {
    tets: &'a [TetData],
    inc_offsets: &'a [u32],
    inc: &'a [(u32, u8)],
    mass: &'a [f32],
    max_step: &'a [f32],
    u: &'a [Vec3],
    y: &'a [Vec3],
    u_prev: &'a [Vec3],
    lame: Lame,
    inv_h2: f32,
    kd_over_h: f32,
}

impl Local<'_> {
    /// The new displacement of node `i` after one safeguarded Newton step on `G_i`.
    #[inline]
    fn solve(&self, i: usize) -> Vec3 {
        let ui = self.u[i];
        let m = self.mass[i] * self.inv_h2;
        let mut f = -(ui - self.y[i]) * m;
        let mut hess = Mat3::IDENTITY * m;
        let range = self.inc_offsets[i] as usize..self.inc_offsets[i + 1] as usize;
        for &(t, a) in &self.inc[range] {
            let t = &self.tets[t as usize];
            let du = t.nodes.map(|n| self.u[n as usize]);
            let s = Strain::of(displacement_gradient(&du, &t.dm_inv));
            let (g, hb) = vertex_gradient_hessian(&s, self.lame, t.volume, t.b[a as usize]);
            f -= g;
            hess += hb;
            if self.kd_over_h > 0.0 {
                // §3.5: Rayleigh damping, D = k_d ∂²E/∂x_i², force −D (x_i − x_iᵗ)/h.
                f -= hb * (ui - self.u_prev[i]) * self.kd_over_h;
                hess += hb * self.kd_over_h;
            }
        }
        let det = hess.determinant();
        if !(det.is_finite() && det > 0.0) {
            return ui;
        }
        let mut dx = hess.inverse() * f;
        let len = dx.length();
        // Line-search-free safeguard: cap the step at a fraction of the local edge length.
        if len > self.max_step[i] {
            dx *= self.max_step[i] / len;
        }
        if dx.is_finite() { ui + dx } else { ui }
    }
}

/// CPU Vertex Block Descent solver for the rest-free Neo-Hookean energy.
pub struct VbdSolver {
    mesh: TetMesh,
    lame: Lame,
    params: VbdParams,
    tets: Vec<TetData>,
    inc_offsets: Vec<u32>,
    inc: Vec<(u32, u8)>,
    colors: Vec<Vec<u32>>,
    mass: Vec<f32>,
    max_step: Vec<f32>,
    kind: Vec<NodeKind>,
    grabs: Vec<Grab>,
    start: Vec<Vec3>,
    u: Vec<Vec3>,
    u_prev: Vec<Vec3>,
    y: Vec<Vec3>,
    v: Vec<Vec3>,
    v_prev: Vec<Vec3>,
    x: Vec<Vec3>,
    cheb_m1: Vec<Vec3>,
    cheb_m2: Vec<Vec3>,
    buf: Vec<Vec3>,
    frame: u64,
    time: f64,
    pool: Option<rayon::ThreadPool>,
}

impl VbdSolver {
    /// A solver for `mesh` made of `material`, starting at rest.
    pub fn new(mesh: TetMesh, material: Material, params: VbdParams) -> Result<Self, VbdError> {
        material.validate()?;
        params.validate()?;
        let lame = material.lame();
        let n = mesh.node_count();
        let tets: Vec<TetData> = (0..mesh.tet_count())
            .map(|t| TetData {
                nodes: mesh.tets[t],
                dm_inv: mesh.dm_inv[t],
                volume: mesh.rest_volume[t],
                b: shape_gradients(&mesh.dm_inv[t]),
            })
            .collect();
        let (inc_offsets, inc) = (mesh.node_tet_offsets.clone(), mesh.node_corners());
        let mut max_step = vec![f32::INFINITY; n];
        let frac = params.max_step_fraction;
        for (i, step) in max_step.iter_mut().enumerate() {
            for &t in mesh.tets_of_node(i) {
                for &k in &mesh.tets[t as usize] {
                    if k as usize != i {
                        let e = (mesh.rest_positions[k as usize] - mesh.rest_positions[i]).length();
                        *step = step.min(frac * e);
                    }
                }
            }
        }
        let (color, ncolors) = greedy_vertex_colors(n, &mesh.tets);
        let mass = mesh.lumped_masses(material.density);
        let mut kind = vec![NodeKind::Free; n];
        for i in 0..n {
            if mass[i] <= 0.0 {
                kind[i] = NodeKind::Retired;
            }
        }
        let mut colors = vec![Vec::new(); ncolors];
        for i in 0..n {
            colors[color[i] as usize].push(i as u32);
        }
        let pool = match params.threads {
            1 => None,
            t => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .map_err(|e| VbdError::ThreadPool {
                        threads: t,
                        msg: e.to_string(),
                    })?,
            ),
        };
        Ok(VbdSolver {
            x: mesh.rest_positions.clone(),
            lame,
            params,
            tets,
            inc_offsets,
            inc,
            colors,
            mass,
            max_step,
            kind,
            grabs: Vec::new(),
            start: vec![Vec3::ZERO; n],
            u: vec![Vec3::ZERO; n],
            u_prev: vec![Vec3::ZERO; n],
            y: vec![Vec3::ZERO; n],
            v: vec![Vec3::ZERO; n],
            v_prev: vec![Vec3::ZERO; n],
            cheb_m1: vec![Vec3::ZERO; n],
            cheb_m2: vec![Vec3::ZERO; n],
            buf: Vec::new(),
            frame: 0,
            time: 0.0,
            pool,
            mesh,
        })
    }

    /// Fix `nodes` at their current positions.
    pub fn pin(&mut self, nodes: &[u32]) {
        for &i in nodes {
            let i = i as usize;
            if self.kind[i] != NodeKind::Retired {
                self.kind[i] = NodeKind::Pinned;
                self.v[i] = Vec3::ZERO;
            }
        }
    }

    /// Move `grab.nodes` kinematically along the grab's path from their current positions
    /// ([`Grab::offset_at`], as the XPBD solver does).
    pub fn add_grab(&mut self, grab: Grab) {
        let k = self.grabs.len() as u32;
        for &i in &grab.nodes {
            let i = i as usize;
            if self.kind[i] != NodeKind::Retired {
                self.kind[i] = NodeKind::Grabbed(k);
                self.start[i] = self.u[i];
            }
        }
        self.grabs.push(grab);
    }

    /// World positions `X + u` at the end of the last frame.
    pub fn positions(&self) -> &[Vec3] {
        &self.x
    }

    /// Displacements from rest.
    pub fn displacements(&self) -> &[Vec3] {
        &self.u
    }

    /// Node velocities, m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.v
    }

    /// The mesh.
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// Settings.
    pub fn params(&self) -> &VbdParams {
        &self.params
    }

    /// Lamé parameters.
    pub fn lame(&self) -> Lame {
        self.lame
    }

    /// Number of vertex colours (parallel passes per iteration).
    pub fn color_count(&self) -> usize {
        self.colors.len()
    }

    /// Simulation time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Frames stepped.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Cauchy von Mises stress of every tet (the rest-free pair's stress), Pa.
    pub fn von_mises(&self) -> Vec<f32> {
        self.tets
            .iter()
            .map(|t| {
                let du = t.nodes.map(|n| self.u[n as usize]);
                let s = Strain::of(displacement_gradient(&du, &t.dm_inv));
                von_mises(&cauchy_stress(&s, self.lame, ConstraintPair::RestFree, 0.0))
            })
            .collect()
    }

    /// Total elastic energy `Σ V Ψ`, J.
    pub fn elastic_energy(&self) -> f64 {
        self.tets
            .iter()
            .map(|t| {
                let du = t.nodes.map(|n| self.u[n as usize]);
                let s = Strain::of(displacement_gradient(&du, &t.dm_inv));
                (t.volume * energy_density(&s, self.lame)) as f64
            })
            .sum()
    }

    /// Advance one frame of `params.substeps` implicit-Euler substeps.
    pub fn step_frame(&mut self) -> Result<VbdFrameStats, VbdError> {
        let t0 = Instant::now();
        match self.pool.take() {
            Some(pool) => {
                pool.install(|| self.run_substeps(true));
                self.pool = Some(pool);
            }
            None => self.run_substeps(false),
        }
        self.time += self.params.frame_dt as f64;
        self.frame += 1;
        if let Some(node) = self.u.iter().position(|u| !u.is_finite()) {
            return Err(VbdError::NonFinite {
                node,
                frame: self.frame,
            });
        }
        for ((x, r), u) in self
            .x
            .iter_mut()
            .zip(&self.mesh.rest_positions)
            .zip(&self.u)
        {
            *x = *r + *u;
        }
        Ok(VbdFrameStats {
            solve_ms: t0.elapsed().as_secs_f64() * 1e3,
        })
    }

    fn run_substeps(&mut self, parallel: bool) {
        let h = self.params.substep();
        for s in 0..self.params.substeps {
            let t = self.time + (s + 1) as f64 * h as f64;
            self.predict(h, t);
            let rho = self.params.chebyshev_rho;
            if rho.is_some() {
                self.cheb_m1.clone_from(&self.u);
            }
            let mut omega = 1.0;
            for n in 1..=self.params.iterations {
                for c in 0..self.colors.len() {
                    self.sweep_color(c, h, parallel);
                }
                if let Some(rho) = rho {
                    omega = chebyshev_omega(n, rho, omega);
                    self.accelerate(n, omega);
                }
            }
            self.update_velocities(h);
        }
    }

    /// Inertial target `y = uᵗ + h vᵗ + h² g` (§3.1) and the initial guess (§3.7);
    /// kinematic nodes jump to their targets at the end of the substep.
    fn predict(&mut self, h: f32, t: f64) {
        let g = self.params.gravity;
        let g_len = g.length();
        let g_dir = if g_len > 0.0 { g / g_len } else { Vec3::ZERO };
        let offsets: Vec<Vec3> = self.grabs.iter().map(|gr| gr.offset_at(t)).collect();
        for i in 0..self.u.len() {
            self.u_prev[i] = self.u[i];
            match self.kind[i] {
                NodeKind::Free => {
                    let (u, v) = (self.u[i], self.v[i]);
                    self.y[i] = u + h * v + h * h * g;
                    self.u[i] = match self.params.initial_guess {
                        InitialGuess::Previous => u,
                        InitialGuess::Inertia => u + h * v,
                        InitialGuess::InertiaAndGravity => self.y[i],
                        InitialGuess::Adaptive => {
                            let a = (v - self.v_prev[i]) / h;
                            let k = if g_len > 0.0 {
                                (a.dot(g_dir) / g_len).clamp(0.0, 1.0)
                            } else {
                                0.0
                            };
                            u + h * v + h * h * k * g
                        }
                    };
                }
                NodeKind::Grabbed(k) => {
                    self.u[i] = self.start[i] + offsets[k as usize];
                    self.y[i] = self.u[i];
                }
                NodeKind::Pinned | NodeKind::Retired => self.y[i] = self.u[i],
            }
        }
    }

    /// One Newton step for every free node of colour `c` (no two share a tet, so their
    /// solves read no value another writes).
    fn sweep_color(&mut self, c: usize, h: f32, parallel: bool) {
        let nodes = &self.colors[c];
        let local = Local {
            tets: &self.tets,
            inc_offsets: &self.inc_offsets,
            inc: &self.inc,
            mass: &self.mass,
            max_step: &self.max_step,
            u: &self.u,
            y: &self.y,
            u_prev: &self.u_prev,
            lame: self.lame,
            inv_h2: 1.0 / (h * h),
            kd_over_h: self.params.stiffness_damping / h,
        };
        let kind = &self.kind;
        let solve = |&i: &u32| {
            let i = i as usize;
            if kind[i] == NodeKind::Free {
                local.solve(i)
            } else {
                local.u[i]
            }
        };
        if parallel && nodes.len() > CHUNK {
            nodes
                .par_iter()
                .with_min_len(CHUNK)
                .map(solve)
                .collect_into_vec(&mut self.buf);
        } else {
            self.buf.clear();
            self.buf.extend(nodes.iter().map(solve));
        }
        for (&i, &u) in nodes.iter().zip(&self.buf) {
            self.u[i as usize] = u;
        }
    }

    /// §3.8: `x⁽ⁿ⁾ = ω_n (x̄⁽ⁿ⁾ − x⁽ⁿ⁻²⁾) + x⁽ⁿ⁻²⁾` for free nodes (ω_1 = 1).
    fn accelerate(&mut self, n: u32, omega: f32) {
        if n >= 2 {
            for i in 0..self.u.len() {
                if self.kind[i] == NodeKind::Free {
                    self.u[i] = omega * (self.u[i] - self.cheb_m2[i]) + self.cheb_m2[i];
                }
            }
        }
        std::mem::swap(&mut self.cheb_m2, &mut self.cheb_m1);
        self.cheb_m1.clone_from(&self.u);
    }

    /// `v = (u − uᵗ)/h`, then the velocity damping of the XPBD solver.
    fn update_velocities(&mut self, h: f32) {
        let keep = (1.0 - self.params.damping * h).max(0.0);
        for i in 0..self.u.len() {
            self.v_prev[i] = self.v[i];
            self.v[i] = match self.kind[i] {
                NodeKind::Free => (self.u[i] - self.u_prev[i]) / h * keep,
                _ => Vec3::ZERO,
            };
        }
    }
}
