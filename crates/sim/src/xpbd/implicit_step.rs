//! The tet solver's frame under `scheme: Newton`: `steps` implicit Euler steps, each the
//! minimisation of `crate::implicit`'s `G` (prediction as the XPBD loop's, then Newton
//! iterations instead of sweeps) with the nodes in the tool's path held where it pushes
//! them (docs/physics-notes.md, "The implicit scheme under a blade"), then the tool contact
//! for the nodes the solve carried into it, the velocity update with the same damping and
//! the release checks on the same simulation-time schedule (PHYSICS.md §1.4), so stress,
//! release and contact are those of the XPBD scheme.

use super::neo_hookean::deformation_gradient_from_displacement;
use super::release_schedule::release_checks;
use super::solver::{NodeKind, Solver};
use super::{CpuKernel, SolverError};
use glam::Vec3;
use std::time::Instant;

use crate::implicit::{NewtonParams, NewtonWorkspace, Scheme};
use crate::thread_team::{for_each_item, part_count, share};

/// Times a step's solve is repeated with the nodes it carried into the tool held too
/// (docs/physics-notes.md, "The implicit scheme under a blade": one pass more brings the
/// released tets to the reference's on plate_cut; a second costs more and gains nothing).
const CONTACT_RESOLVES: usize = 1;

/// How many times a frame under the blade may be run again at twice the steps
/// (`Solver::run_implicit_steps`): at most 2^3 = 8 times the scene's steps.
pub const MAX_SPLITS: u32 = 3;

/// The positions, velocities and nodes on the blade a frame started from (what
/// `Solver::step_frame` saved for its guards).
pub(crate) type Saved<'a> = (&'a [Vec3], &'a [Vec3], &'a [bool]);

/// What a frame under the blade starts from, to take it back: `step_frame`'s saved state,
/// the near-edge window and how many live tets were inverted.
struct FrameStart<'a> {
    saved: Saved<'a>,
    near_window: Vec<bool>,
    inverted: usize,
}

impl<'a> FrameStart<'a> {
    fn of(s: &Solver, saved: Saved<'a>) -> Self {
        FrameStart {
            saved,
            near_window: s.near_window.clone(),
            inverted: s.inverted_live_tets(&[]),
        }
    }

    /// Back to the frame's start: the tets its release checks switched off live again.
    fn restore(&self, s: &mut Solver) {
        let (u, v, touched) = self.saved;
        s.u.copy_from_slice(u);
        s.v.copy_from_slice(v);
        s.touched.copy_from_slice(touched);
        s.near_window.clone_from(&self.near_window);
        s.near_edge.iter_mut().for_each(|b| *b = false);
        s.contact_push.iter_mut().for_each(|p| *p = Vec3::ZERO);
        s.revive_pending();
    }
}

impl Solver {
    /// Build the implicit scheme's workspace (coarse grid, its factorised matrix) now, if
    /// the scheme is Newton and it is not built yet: a scene calls this once its pins and
    /// grabs are set, so the first frame does not pay for it (0.3-0.8 s on the default
    /// organ, a stall a headset user sees). Without the call the first frame builds it.
    pub fn prepare(&mut self) -> Result<(), SolverError> {
        match self.params.scheme {
            Scheme::Newton(p) => self.prepare_implicit(p),
            Scheme::Xpbd => Ok(()),
        }
    }

    /// The Newton workspace for the current free nodes, built once.
    fn prepare_implicit(&mut self, p: NewtonParams) -> Result<(), SolverError> {
        if self.newton.is_some() {
            return Ok(());
        }
        let h = self.params.frame_dt / p.steps as f32;
        let free: Vec<bool> = self.kind.iter().map(|k| *k == NodeKind::Free).collect();
        // The SIMD product unless the scalar reference kernel is asked for.
        let lanes = self.params.cpu_kernel != CpuKernel::Scalar;
        let team = self.team.as_ref();
        let ws = NewtonWorkspace::new(
            &self.mesh,
            &self.mass,
            &free,
            self.lame,
            (h, lanes),
            p,
            team,
        )?;
        self.newton = Some(ws);
        Ok(())
    }

    /// The frame's implicit steps; returns whether a release check ran after the last one
    /// (the stress is then current). With a tool attached, a frame after which more live
    /// tets are inverted than before it is taken back (positions, velocities, the nodes
    /// on the blade, the push, its releases) and run again at twice the steps, up to
    /// `MAX_SPLITS` times (docs/physics-notes.md, "The implicit scheme under a blade").
    pub(crate) fn run_implicit_steps(
        &mut self,
        p: NewtonParams,
        saved: Saved,
    ) -> Result<bool, SolverError> {
        self.prepare_implicit(p)?;
        self.implicit_cost = Default::default();
        self.check_ms = 0.0;
        self.passes = 0;
        let start = self.tool.is_some().then(|| FrameStart::of(self, saved));
        let mut n = p.steps;
        loop {
            let fresh = self.implicit_steps(n);
            let Some(start) = &start else {
                return Ok(fresh);
            };
            if n >= p.steps << MAX_SPLITS || self.inverted_live_tets(&[]) <= start.inverted {
                return Ok(fresh);
            }
            start.restore(self);
            self.implicit_cost.split_frames += 1;
            n *= 2;
        }
    }

    /// `n` implicit steps over the frame with the release checks that fall in them.
    fn implicit_steps(&mut self, n: u32) -> bool {
        let h = self.params.frame_dt / n as f32;
        if let Some(ws) = &mut self.newton {
            ws.set_step_length(h);
        }
        let free: Vec<bool> = self.kind.iter().map(|k| *k == NodeKind::Free).collect();
        let checks = release_checks(self.time, h, n, self.params.release_interval);
        let mut next = checks.iter().peekable();
        let mut fresh = false;
        self.passes += checks.len() as u32;
        for s in 0..n {
            let held = self.implicit_step((s, n), &free);
            fresh = next.next_if(|&&k| k == s).is_some();
            if fresh {
                let before = self.pending.len();
                self.release_check();
                self.unload_released(h, &held, before);
            }
        }
        fresh
    }

    /// Failed tissue carries no load: the tets the step's release check switched off
    /// (`pending[from..]`) taken out of the reactions booked at the nodes the step `held`
    /// (a tet crushed under the blade fails the check; its force, which can reach
    /// hundreds of newtons as it inverts, would otherwise reach the tool for the frame).
    fn unload_released(&mut self, h: f32, held: &[bool], from: usize) {
        let Some(ws) = &self.newton else {
            return;
        };
        for &t in &self.pending[from..] {
            for (a, &k) in self.mesh.tets[t as usize].iter().enumerate() {
                if held[k as usize] {
                    self.contact_push[k as usize] -= h * h * ws.corner_reaction(t as usize, a);
                }
            }
        }
    }

    /// One implicit Euler step, `s` of `n` in the frame: prediction, the nodes in the
    /// tool's path held, the solve (again with the nodes it carried into the tool), the
    /// held nodes' reactions, contact and velocities; returns the nodes it held.
    fn implicit_step(&mut self, (s, n): (u32, u32), free: &[bool]) -> Vec<bool> {
        let h = self.params.frame_dt / n as f32;
        let t = self.time + (s + 1) as f64 * h as f64;
        self.predict(h, t);
        // PHYSICS.md §1.5 inside the step (docs/physics-notes.md, "The implicit scheme
        // under a blade"): the nodes in the tool's path are held where it pushes them.
        let mut held = vec![false; free.len()];
        self.hold_contacts(s, n, &mut held);
        // A held node's target is where the tool holds it.
        let y = self.u.clone();
        // Start from u + h v without this step's gravity: y itself drops every free
        // node by h²g (2.7 mm at 60 Hz, a tet's height) while the pins hold, which
        // crushes the tets along the pins in the first iterate.
        let fall = self.params.gravity * (h * h);
        for (i, u) in self.u.iter_mut().enumerate() {
            if free[i] && !held[i] {
                *u -= fall;
            }
        }
        let live = self.live_tets();
        for pass in 0..=CONTACT_RESOLVES {
            let step_free: Vec<bool> = free.iter().zip(&held).map(|(f, h)| *f && !*h).collect();
            self.implicit_solve(&y, &live, &step_free);
            if pass == CONTACT_RESOLVES {
                break;
            }
            // Nodes the solve carried into the tool: held too, and solved again.
            let moved = self.contacts(s, n);
            if moved.is_empty() {
                break;
            }
            for (i, _) in moved {
                held[i] = true;
            }
        }
        self.push_held(h, &y, &held);
        self.project_contacts(s, n);
        self.update_velocities(h);
        held
    }

    /// Do now what the coming frame can do before it knows the tool's pose: under
    /// `scheme: Newton`, the coarse matrix's refactorisation after the last frame's
    /// releases ([`NewtonWorkspace::settle_coarse`]); the frame does it itself when this
    /// was not called, to the same bits. A caller that reads the tool's pose just before
    /// each frame (the headset's simulation thread) calls this after showing the last
    /// one, so the frame's step starts sooner after its pose. Its time is the next
    /// frame's `ahead_ms`.
    pub fn prepare_frame(&mut self) {
        let started = Instant::now();
        if let Some(ws) = &mut self.newton
            && ws.settle_coarse()
        {
            self.ahead_ms += started.elapsed().as_secs_f64() * 1e3;
        }
    }

    /// Live tets whose volume ratio `J` is at most 0 where the nodes stand now, leaving
    /// out `gone` (tets released but not yet switched off in this mirror: the device's).
    pub(crate) fn inverted_live_tets(&self, gone: &[u32]) -> usize {
        let mut live = self.live_tets();
        for &t in gone {
            live[t as usize] = false;
        }
        let inverted = |t: usize| {
            live[t] && {
                let d = self.mesh.tets[t].map(|k| self.u[k as usize]);
                deformation_gradient_from_displacement(&d, &self.mesh.dm_inv[t]).determinant()
                    <= 0.0
            }
        };
        // Counted per part on the team (one count a part), the parts' counts summed.
        let (n, team) = (self.mesh.tet_count(), self.team.as_ref());
        let mut counts = vec![0; part_count(team, n, 1024)];
        let parts = counts.len();
        for_each_item(team, &mut counts, 1, |p, count| {
            *count = share(n, p, parts).filter(|&t| inverted(t)).count();
        });
        counts.iter().sum()
    }

    /// One Newton solve of the step from `u` to the minimum of `G` (target `y`), the nodes
    /// not `free` held; its cost booked.
    fn implicit_solve(&mut self, y: &[Vec3], live: &[bool], free: &[bool]) {
        if let Some(ws) = &mut self.newton {
            ws.solve(&mut self.u, y, live, free, self.team.as_ref());
            let r = ws.last;
            self.implicit_cost.add(&r);
            self.coarse_nodes = r.coarse_nodes;
            // A tet pass and a node pass per evaluation, product and gather.
            self.passes += 2 * (1 + r.iterations + r.halvings) + 2 * r.cg_products + r.iterations;
        }
    }

    /// The force that held each `held` node, `∂G/∂x` there (PHYSICS.md §1.5's contact
    /// multiplier `λ = h² f`), booked as the tool's push.
    fn push_held(&mut self, h: f32, y: &[Vec3], held: &[bool]) {
        let Some(ws) = &self.newton else {
            return;
        };
        for i in (0..held.len()).filter(|&i| held[i]) {
            self.contact_push[i] += h * h * ws.reaction(&self.u, y, i);
            self.touched[i] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xpbd::SolverParams;
    use crate::xpbd::solver::tests::soft_block;

    /// A 6,144-tet block on `threads`, every third node pushed through its neighbours.
    fn crushed(threads: usize) -> Solver {
        let params = SolverParams {
            threads,
            ..SolverParams::default()
        };
        let cells = (Vec3::new(0.08, 0.04, 0.02), glam::UVec3::new(16, 8, 8));
        soft_block(cells, params, |i| match i % 6 {
            0 => Vec3::Z * -0.004,
            3 => Vec3::Z * 0.004,
            _ => Vec3::ZERO,
        })
    }

    /// The count of inverted live tets is the same counted in parts on a team as on one
    /// thread, and leaves out the tets named gone.
    #[test]
    fn inverted_tets_are_counted_alike_on_a_team() {
        let (one, team) = (crushed(1), crushed(2));
        assert!(team.team.is_some(), "two threads make a team");
        let gone: Vec<u32> = (0..100).collect();
        let serial = |gone: &[u32]| {
            (0..one.mesh.tet_count() as u32)
                .filter(|t| !gone.contains(t))
                .filter(|&t| {
                    let d = one.mesh.tets[t as usize].map(|k| one.u[k as usize]);
                    let dm_inv = &one.mesh.dm_inv[t as usize];
                    deformation_gradient_from_displacement(&d, dm_inv).determinant() <= 0.0
                })
                .count()
        };
        let (all, some) = (serial(&[]), serial(&gone));
        assert!(
            all > 100 && some < all,
            "crushed: {all} inverted, {some} without the gone"
        );
        assert_eq!(one.inverted_live_tets(&[]), all);
        assert_eq!(team.inverted_live_tets(&[]), all);
        assert_eq!(team.inverted_live_tets(&gone), some);
    }
}
