//! A frame of the implicit scheme on the device: per implicit step the XPBD solver's
//! prediction kernel, the blade's held nodes (the contact kernel's `hold`), the Newton
//! solve (`gpu/newton/`; once more when `resolve` held the nodes it carried into the
//! tool), the held nodes' reactions, then the contact, velocity and release-check kernels
//! on the same simulation-time schedule. CPU twin: `Solver::run_implicit_steps`
//! (crates/sim/src/xpbd/implicit_step.rs).

use super::{GpuSolver, groups};
use crate::gpu::GpuError;
use crate::gpu::newton::OnDevice;
use crate::gpu::readback::read_mapped;
use crate::xpbd::release_checks;

impl GpuSolver {
    /// Record and run the frame's implicit steps after the commands already in `enc`
    /// (each Newton evaluation submits and reads back); returns the encoder holding the
    /// frame's last commands, the stress pass included. Sets the host's pass count (the
    /// frame's dispatches) and its conjugate-gradient cost.
    pub(super) fn record_newton_frame(
        &mut self,
        enc: wgpu::CommandEncoder,
        n: u32,
    ) -> Result<wgpu::CommandEncoder, GpuError> {
        let Some(mut newton) = self.newton.take() else {
            return Ok(enc);
        };
        newton.dispatches = 0;
        let done = self.newton_steps(&mut newton, enc, n);
        self.host.passes += newton.dispatches;
        self.newton = Some(newton);
        done
    }

    /// The `n` steps of [`GpuSolver::record_newton_frame`]; its own dispatches go to the
    /// host's pass count, the Newton solver's to `newton.dispatches`.
    fn newton_steps(
        &mut self,
        newton: &mut crate::gpu::newton::GpuNewton,
        mut enc: wgpu::CommandEncoder,
        n: u32,
    ) -> Result<wgpu::CommandEncoder, GpuError> {
        let p = &self.host.params;
        let h = p.frame_dt / n as f32;
        let checks = release_checks(self.host.time, h, n, p.release_interval);
        let nodes = self.host.x.len();
        let mut fresh = false;
        let mut dispatches = 0;
        for s in 0..n as usize {
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("newton step start"),
                    timestamp_writes: None,
                });
                if s == 0 {
                    // The frame's near-edge bit clears (as in the XPBD frame).
                    pass.set_pipeline(&self.kernels.clear_frame);
                    pass.set_bind_group(0, &self.bind.clear_frame, &[]);
                    pass.dispatch_workgroups(groups(nodes), 1, 1);
                    dispatches += 1;
                }
                pass.set_pipeline(&self.kernels.predict);
                pass.set_bind_group(0, &self.bind.predict, &[]);
                pass.set_bind_group(1, &self.bind.predict_steps[s], &[]);
                pass.dispatch_workgroups(groups(nodes), 1, 1);
                dispatches += 1;
                if self.host.tool.is_some() {
                    pass.set_pipeline(&self.kernels.contact_hold);
                    pass.set_bind_group(0, &self.bind.contact_hold, &[]);
                    pass.set_bind_group(1, &self.bind.hold_steps[s], &[]);
                    pass.dispatch_workgroups(groups(nodes), 1, 1);
                    dispatches += 1;
                }
            }
            newton.start_step(&mut enc);
            let live = self.host.live_tets();
            let dev = OnDevice {
                device: &self.device,
                queue: &self.queue,
                pos: &self.buf.pos,
                read_pos: &self.read.pos,
            };
            let host = (&live[..], self.host.team.as_ref());
            enc = newton.solve_step(&dev, host, enc, false)?;
            let mut r = newton.last;
            if self.host.tool.is_some() {
                dispatches += 1;
                // The nodes the solve carried into the tool, held: solved again if any
                // (CPU twin: the resolve pass of Solver::run_implicit_steps).
                if self.record_resolve(enc, s)? > 0 {
                    self.host.implicit_cost.add(&r);
                    let host = (&live[..], self.host.team.as_ref());
                    enc = newton.solve_step(&dev, host, new_encoder(&self.device), true)?;
                    r = newton.last;
                } else {
                    enc = new_encoder(&self.device);
                }
                newton.record_reaction(&mut enc);
            }
            self.host.implicit_cost.add(&r);
            self.host.coarse_nodes = r.coarse_nodes;
            fresh = checks.contains(&(s as u32));
            dispatches += self.record_step_end(&mut enc, s, fresh);
            if self.host.tool.is_some() {
                // After every step, so a held node's mark clears (without a check no tet
                // went since the solve, and nothing is given back).
                newton.record_unload(&mut enc);
            }
        }
        if !fresh {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("newton frame stress"),
                timestamp_writes: None,
            });
            dispatches += self.record_stress(&mut pass);
        }
        self.host.passes = dispatches;
        Ok(enc)
    }

    /// Record step `s`'s end after `enc`: the contact with a tool, the velocities and,
    /// when `check`, the release check; returns the dispatches.
    fn record_step_end(&self, enc: &mut wgpu::CommandEncoder, s: usize, check: bool) -> u32 {
        let nodes = self.host.x.len();
        let mut dispatches = 0;
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("newton step end"),
            timestamp_writes: None,
        });
        if self.host.tool.is_some() {
            pass.set_pipeline(&self.kernels.contact);
            pass.set_bind_group(0, &self.bind.contact, &[]);
            pass.set_bind_group(1, &self.bind.contact_steps[s], &[]);
            pass.dispatch_workgroups(groups(nodes), 1, 1);
            dispatches += 1;
        }
        pass.set_pipeline(&self.kernels.velocity);
        pass.set_bind_group(0, &self.bind.velocity, &[]);
        pass.dispatch_workgroups(groups(nodes), 1, 1);
        dispatches += 1;
        if check {
            dispatches += self.record_release_check(&mut pass);
        }
        dispatches
    }

    /// Record the contact kernel's `resolve` for step `s` after `enc`, submit and read how
    /// many nodes it held.
    fn record_resolve(&self, mut enc: wgpu::CommandEncoder, s: usize) -> Result<u32, GpuError> {
        enc.clear_buffer(&self.buf.moved, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("newton contact resolve"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.kernels.contact_resolve);
            pass.set_bind_group(0, &self.bind.contact_resolve, &[]);
            pass.set_bind_group(1, &self.bind.resolve_steps[s], &[]);
            pass.dispatch_workgroups(groups(self.host.x.len()), 1, 1);
        }
        enc.copy_buffer_to_buffer(&self.buf.moved, 0, &self.read.moved, 0, 4);
        self.queue.submit([enc.finish()]);
        let got = read_mapped::<u32>(&self.device, &[&self.read.moved])?;
        let count = got[0][0];
        Ok(count)
    }
}

/// A new command encoder for the rest of a Newton step.
fn new_encoder(device: &wgpu::Device) -> wgpu::CommandEncoder {
    device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("newton step"),
    })
}
