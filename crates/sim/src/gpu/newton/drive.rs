//! One implicit Euler step on the device, driven from the host as `NewtonWorkspace::solve`
//! drives the CPU's (crates/sim/src/implicit/workspace.rs): evaluate the first iterate,
//! then per Newton iteration a conjugate-gradient solve and a backtracking line search on
//! `G`. The host reads back a few sums per submission — the energies and the gradient's
//! norm per evaluation, the solve's state every [`CG_BATCH`] iterations — never per
//! conjugate-gradient iteration: the solve's scalars are reduced and decided on the device
//! (newton_cg.wgsl).

use glam::Vec3;

use super::GpuNewton;
use super::layout::{ALPHA_OFFSET, S_FIRST, S_NEG, S_PRODUCTS, S_STOP, V_TRIAL};
use crate::gpu::GpuError;
use crate::gpu::readback::read_mapped;
use crate::implicit::{FirstTrial, NewtonReport};
use crate::thread_team::ThreadTeam;

/// Armijo constant of the line search (the CPU's).
const ARMIJO: f64 = 1e-4;
/// Most halvings of a Newton step before the step is abandoned (the CPU's).
const MAX_HALVINGS: u32 = 8;
/// Conjugate-gradient iterations recorded per submission after the first (which records
/// as many as the last solve took); the host reads whether the solve has stopped between
/// submissions (a stopped solve's remaining dispatches return at once).
pub(crate) const CG_BATCH: u32 = 4;
/// Most iterations of a first submission.
const CG_FIRST_MAX: u32 = 32;

/// The device, its queue and the node buffers the step reads and writes.
pub(crate) struct OnDevice<'a> {
    /// The device.
    pub device: &'a wgpu::Device,
    /// Its queue.
    pub queue: &'a wgpu::Queue,
    /// Node displacements: the iterate.
    pub pos: &'a wgpu::Buffer,
    /// A mappable copy of `pos` (the coarse refresh reads the first iterate).
    pub read_pos: &'a wgpu::Buffer,
}

/// What one evaluation's readback says.
#[derive(Debug, Clone, Copy)]
struct Sums {
    /// `G` at the evaluated point.
    g: f64,
    /// `|∇G|²` there (after a full evaluation).
    grad2: f64,
    /// `∇G · d` at the current iterate (after a trial point).
    slope: f64,
    /// The furthest a free node moves along `d`, m (after a trial point).
    reach: f32,
}

/// One dispatch: pipeline, group 0, workgroups.
type Dispatch<'a> = (&'a wgpu::ComputePipeline, &'a wgpu::BindGroup, u32);

/// Record `list` in one compute pass; returns how many dispatches (empty ones left out).
fn record(enc: &mut wgpu::CommandEncoder, list: &[Dispatch<'_>]) -> u32 {
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("newton"),
        timestamp_writes: None,
    });
    let mut count = 0;
    for (pipeline, group, workgroups) in list {
        if *workgroups == 0 {
            continue;
        }
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, *group, &[]);
        pass.dispatch_workgroups(*workgroups, 1, 1);
        count += 1;
    }
    count
}

impl GpuNewton {
    /// Record the step's start: the prediction in `pos` (written there by the predict
    /// kernel, then the blade's held nodes by the contact kernel's `hold`) becomes the
    /// target `y`, and the first iterate leaves out this step's fall at the free nodes.
    pub fn start_step(&mut self, enc: &mut wgpu::CommandEncoder) {
        let (ng, _, _) = self.groups;
        self.dispatches += record(enc, &[(&self.kernels.start, &self.bind.nodes, ng)]);
    }

    /// Record the held nodes' reactions into the contact push (after the step's last
    /// solve, before the contact kernel frees them).
    pub fn record_reaction(&mut self, enc: &mut wgpu::CommandEncoder) {
        let (ng, _, _) = self.groups;
        self.dispatches += record(enc, &[(&self.kernels.reaction, &self.bind.nodes, ng)]);
    }

    /// Record the step's unload after its release check: the held nodes' reactions give
    /// back the tets the check switched off (CPU twin: `Solver::unload_released`).
    pub fn record_unload(&mut self, enc: &mut wgpu::CommandEncoder) {
        let (ng, _, _) = self.groups;
        self.dispatches += record(enc, &[(&self.kernels.unload, &self.bind.nodes, ng)]);
    }

    /// Minimise `G` from the iterate in `pos`: right after [`GpuNewton::start_step`]
    /// (which set the point to evaluate), or, `again`, as a further solve of the step
    /// left it and the contact moved it since; `enc` holds the commands recorded so far.
    /// `live` per tet (mesh order) is what a coarse refresh assembles, on the host
    /// solver's `team`. Returns an encoder to record the rest of the frame in.
    pub fn solve_step(
        &mut self,
        dev: &OnDevice<'_>,
        (live, team): (&[bool], Option<&ThreadTeam>),
        mut enc: wgpu::CommandEncoder,
        again: bool,
    ) -> Result<wgpu::CommandEncoder, GpuError> {
        let mut report = NewtonReport::default();
        let refresh = self.coarse.refresh_due(&self.last);
        let (k, b) = (&self.kernels, &self.bind);
        let (ng, tg, _) = self.groups;
        let resume = if again { ng } else { 0 };
        self.dispatches += record(
            &mut enc,
            &[
                (&k.resume, &b.nodes, resume),
                (&k.evaluate, &b.tets, tg),
                (&k.gather, &b.nodes, ng),
            ],
        );
        let (scratch, first_iterate) = self.submit_read(dev, enc, refresh)?;
        let mut now = self.sums(&scratch);
        if let Some(u) = first_iterate {
            report.coarse_refreshed = true;
            report.coarse_refresh_failed = self.coarse.refresh(&u, live, team).is_err();
            self.upload_coarse(dev.queue);
        } else {
            self.settle_coarse(dev.queue);
        }
        self.coarse.tick();
        let mut enc = encoder(dev);
        let mut first_norm = None;
        for _ in 0..self.params.iterations {
            let stop;
            (report.gradient_ratio, stop) =
                self.params.gradient_stop(&mut first_norm, now.grad2.sqrt());
            if stop {
                break;
            }
            let (next, products, negative) = self.conjugate_gradient(dev, enc)?;
            report.iterations += 1;
            report.cg_products += products;
            report.negative_curvature += u32::from(negative);
            let first = FirstTrial::after(negative);
            let (next, taken) = self.line_search(dev, next, now.g, first, &mut report)?;
            enc = next;
            match taken {
                Some((sums, moved)) => {
                    now = sums;
                    if self.params.step_stop(moved, self.mean_edge) {
                        break;
                    }
                }
                None => break,
            }
        }
        report.coarse_nodes = self.coarse.nodes() as u32;
        self.last = report;
        Ok(enc)
    }

    /// Solve `∇²G d = −∇G` into the direction slice: the solve's start, then batches of
    /// iterations until the device says it has stopped. Returns a fresh encoder, the
    /// products spent and whether it met non-positive curvature.
    fn conjugate_gradient(
        &mut self,
        dev: &OnDevice<'_>,
        mut enc: wgpu::CommandEncoder,
    ) -> Result<(wgpu::CommandEncoder, u32, bool), GpuError> {
        let (k, b) = (&self.kernels, &self.bind);
        let (ng, tg, rg) = self.groups;
        self.dispatches += record(
            &mut enc,
            &[
                (&k.restrict_init, &b.cg, 1),
                (&k.coarse_solve, &b.cg, rg),
                (&k.precondition_init, &b.cg, ng),
            ],
        );
        let iteration: [Dispatch<'_>; 5] = [
            (&k.product, &b.tets, tg),
            (&k.gather_product, &b.nodes, ng),
            (&k.step_restrict, &b.cg, 1),
            (&k.coarse_solve, &b.cg, rg),
            (&k.update, &b.cg, ng),
        ];
        let max = self.params.cg_iterations;
        let mut batch = self.cg_hint.clamp(1, CG_FIRST_MAX.min(max));
        let mut dispatches = 0;
        let at = self.scratch.state();
        let tol2 = (self.params.cg_tolerance as f64).powi(2);
        loop {
            let list: Vec<Dispatch<'_>> = (0..batch).flat_map(|_| iteration).collect();
            dispatches += record(&mut enc, &list);
            let (s, _) = self.submit_read(dev, enc, false)?;
            enc = encoder(dev);
            let products = s[at + S_PRODUCTS] as u32;
            let negative = s[at + S_NEG] != 0.0;
            // The device stops at the next product's start; the host sees the same test
            // on the residual the last update left, and records no more.
            let rz: f64 = s[self.scratch.rz()].iter().map(|&v| v as f64).sum();
            let converged = rz <= tol2 * s[at + S_FIRST] as f64;
            if s[at + S_STOP] != 0.0 || negative || converged || products >= max {
                self.dispatches += dispatches;
                self.cg_hint = products;
                return Ok((enc, products, negative));
            }
            batch = CG_BATCH.min(max - products).max(1);
        }
    }

    /// Backtrack along the direction from the iterate until `G` decreases enough (as
    /// `NewtonWorkspace::line_search`): the full step is evaluated as `first` says, a
    /// halved one for its energy only, and a point evaluated for its energy alone in full
    /// once taken. Returns the sums at the point taken and how far the step moved the
    /// furthest free node, or `None` (the iterate stays) when the direction does not
    /// descend or no halving decreased `G`.
    fn line_search(
        &mut self,
        dev: &OnDevice<'_>,
        mut enc: wgpu::CommandEncoder,
        g_now: f64,
        first: FirstTrial,
        report: &mut NewtonReport,
    ) -> Result<(wgpu::CommandEncoder, Option<(Sums, f32)>), GpuError> {
        let mut alpha = 1.0f32;
        // f32 energies summed in f64 on the host: changes below this are rounding.
        let rounding = 1e-6 * g_now.abs();
        let (mut slope, mut reach) = (0.0, 0.0);
        for halving in 0..=MAX_HALVINGS {
            dev.queue
                .write_buffer(&self.buf.uniform, ALPHA_OFFSET, bytemuck::bytes_of(&alpha));
            let (k, b) = (&self.kernels, &self.bind);
            let (ng, tg, _) = self.groups;
            let full = halving == 0 && first == FirstTrial::Full;
            let list = if full {
                [
                    (&k.trial, &b.nodes, ng),
                    (&k.evaluate, &b.tets, tg),
                    (&k.gather, &b.nodes, ng),
                ]
            } else {
                [
                    (&k.trial, &b.nodes, ng),
                    (&k.energy, &b.tets, tg),
                    (&k.inertia, &b.nodes, ng),
                ]
            };
            self.dispatches += record(&mut enc, &list);
            let (s, _) = self.submit_read(dev, enc, false)?;
            enc = encoder(dev);
            let mut at = self.sums(&s);
            if halving == 0 {
                (slope, reach) = (at.slope, at.reach);
                if slope >= 0.0 {
                    return Ok((enc, None));
                }
            }
            if at.g <= g_now + ARMIJO * alpha as f64 * slope + rounding {
                if !full {
                    let (k, b) = (&self.kernels, &self.bind);
                    self.dispatches += record(
                        &mut enc,
                        &[(&k.evaluate, &b.tets, tg), (&k.gather, &b.nodes, ng)],
                    );
                    let (s, _) = self.submit_read(dev, enc, false)?;
                    enc = encoder(dev);
                    at.grad2 = self.sums(&s).grad2;
                }
                let n = self.node_count as u64;
                enc.copy_buffer_to_buffer(&self.buf.vecs, V_TRIAL * n * 16, dev.pos, 0, n * 16);
                return Ok((enc, Some((at, alpha * reach))));
            }
            alpha *= 0.5;
            report.halvings += 1;
        }
        Ok((enc, None))
    }

    /// `G`, `|∇G|²` and the slope from the partial sums of a readback.
    // PHYSICS.md §1.2's energy plus the inertia: G = Σ V Ψ + 1/(2h²) Σ m |u − y|²
    // (crates/sim/src/implicit/workspace.rs).
    fn sums(&self, s: &[f32]) -> Sums {
        let sum = |r: std::ops::Range<usize>| s[r].iter().map(|&v| v as f64).sum::<f64>();
        let sc = &self.scratch;
        Sums {
            g: sum(sc.tet_energy()) + 0.5 * self.inv_h2 as f64 * sum(sc.inertia()),
            grad2: sum(sc.grad2()),
            slope: sum(sc.slope()),
            reach: s[sc.reach()].iter().fold(0.0f32, |a, &b| a.max(b)).sqrt(),
        }
    }

    /// Submit `enc` with a copy of the scratch (and, with `positions`, of the iterate),
    /// wait, and read them.
    fn submit_read(
        &self,
        dev: &OnDevice<'_>,
        mut enc: wgpu::CommandEncoder,
        positions: bool,
    ) -> Result<(Vec<f32>, Option<Vec<Vec3>>), GpuError> {
        let bytes = 4 * self.scratch.len() as u64;
        let pos_bytes = 16 * self.node_count as u64;
        enc.copy_buffer_to_buffer(&self.buf.scratch, 0, &self.buf.read_scratch, 0, bytes);
        if positions {
            enc.copy_buffer_to_buffer(dev.pos, 0, dev.read_pos, 0, pos_bytes);
        }
        dev.queue.submit([enc.finish()]);
        let mut bufs = vec![&self.buf.read_scratch];
        if positions {
            bufs.push(dev.read_pos);
        }
        let mut got = read_mapped::<f32>(dev.device, &bufs)?.into_iter();
        let scratch = got.next().unwrap_or_default();
        let u = got
            .next()
            .map(|p| p.chunks(4).map(|c| Vec3::new(c[0], c[1], c[2])).collect());
        Ok((scratch, u))
    }
}

/// A new command encoder.
fn encoder(dev: &OnDevice<'_>) -> wgpu::CommandEncoder {
    dev.device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("newton"),
        })
}
