//! Forces and time integration of the mass-spring model (PHYSICS.md §2.1, eqs. 1–2).
//!
//! Eq. 2 is semi-implicit (symplectic) Euler: `v += Δt a; p += Δt v` with the new
//! velocity. The node damping `−b v` of eq. 1 is taken implicitly,
//! `v' = (v + Δt (F_spring/m + g)) / (1 + Δt b/m)`, which is unconditionally stable for
//! the damping and equal to eq. 2 to first order; the springs set the step bound
//! ([`MassSpringModel::stable_dt`]).

use glam::DVec3;

use super::MassSpringModel;

/// Fraction of the spring stability bound `2/ω_max` used as the step.
const STABILITY_SAFETY: f64 = 0.8;

impl MassSpringModel {
    /// Sum of the spring forces on node `i`: `Σ k_e (l − l0) u` over its springs.
    // PHYSICS.md §2.1, eq. 1 (F_spring).
    #[inline]
    pub fn spring_force(&self, i: usize) -> DVec3 {
        let x = self.positions[i];
        let mut f = DVec3::ZERO;
        for s in &self.springs[i] {
            let d = self.positions[s.node as usize] - x;
            let l = d.length();
            if l > 0.0 {
                f += d * (s.stiffness * (l - s.rest) / l);
            }
        }
        f
    }

    /// The largest stable step for the springs, s: `0.8 · 2/ω_max` with
    /// `ω_max² ≤ max_i Σ_j k_ij (1/m_i + 1/√(m_i m_j))` (Gershgorin on `M^{-1/2} K M^{-1/2}`).
    pub fn stable_dt(&self) -> f64 {
        self.stable_dt
    }

    /// Recompute [`MassSpringModel::stable_dt`] (after masses or springs changed).
    pub fn refresh_stability(&mut self) {
        let w2 = (0..self.node_count())
            .map(|i| self.stiffness_row(i))
            .fold(0.0, f64::max);
        self.stable_dt = if w2 > 0.0 {
            (STABILITY_SAFETY * 2.0 / w2.sqrt()).min(self.params.max_dt)
        } else {
            self.params.max_dt
        };
    }

    /// Lower [`MassSpringModel::stable_dt`] if the bound at `nodes` (after a local change)
    /// asks for a smaller step; cheaper than a full refresh.
    pub fn refresh_stability_near(&mut self, nodes: &[u32]) {
        let w2 = nodes
            .iter()
            .map(|&i| self.stiffness_row(i as usize))
            .fold(0.0, f64::max);
        if w2 > 0.0 {
            self.stable_dt = self.stable_dt.min(STABILITY_SAFETY * 2.0 / w2.sqrt());
        }
    }

    /// Gershgorin row bound of `ω²` at node `i` (0 for pinned or massless nodes).
    fn stiffness_row(&self, i: usize) -> f64 {
        let mi = self.masses[i];
        if mi <= 0.0 || self.fixed[i].is_pinned() {
            return 0.0;
        }
        self.springs[i]
            .iter()
            .map(|s| {
                let mj = self.masses[s.node as usize];
                s.stiffness
                    * (1.0 / mi
                        + if mj > 0.0 {
                            1.0 / (mi * mj).sqrt()
                        } else {
                            0.0
                        })
            })
            .sum()
    }

    /// Total force on node `i`: its springs plus any external force, N.
    // PHYSICS.md §2.1, eq. 1 (gravity enters as an acceleration in eq. 2).
    #[inline]
    fn node_force(&self, i: usize) -> DVec3 {
        let mut f = self.spring_force(i);
        for &(n, e) in &self.external {
            if n as usize == i {
                f += e;
            }
        }
        f
    }

    /// New velocity of node `i` under force `f` after a step `dt` (eq. 2 with implicit
    /// node damping).
    // PHYSICS.md §2.1, eqs. 1–2.
    #[inline]
    fn stepped_velocity(&self, i: usize, f: DVec3, dt: f64) -> DVec3 {
        let m = self.masses[i];
        if m <= 0.0 {
            return DVec3::ZERO;
        }
        let a = f / m + self.params.gravity;
        let v = (self.velocities[i] + dt * a) / (1.0 + dt * self.params.damping / m);
        self.fixed[i].free_part(v)
    }

    /// The force phase of a step for `nodes`: their total forces into `out` (cleared).
    pub fn gather_forces(&self, nodes: &[u32], out: &mut Vec<DVec3>) {
        out.clear();
        out.extend(nodes.iter().map(|&i| self.node_force(i as usize)));
    }

    /// The integration phase of a step of `dt` for `nodes` under `forces` (from
    /// [`MassSpringModel::gather_forces`] for the same nodes); other nodes stay in place.
    // PHYSICS.md §2.1, eq. 2.
    pub fn integrate_nodes(&mut self, dt: f64, nodes: &[u32], forces: &[DVec3]) {
        for (&i, &f) in nodes.iter().zip(forces) {
            let i = i as usize;
            let v = self.stepped_velocity(i, f, dt);
            self.velocities[i] = v;
            self.positions[i] += dt * v;
        }
        self.time += dt;
    }

    /// One explicit step of `dt` for every node.
    pub fn step(&mut self, dt: f64) {
        let n = self.node_count();
        let mut f = std::mem::take(&mut self.scratch);
        f.clear();
        f.extend((0..n).map(|i| self.node_force(i)));
        for (i, f) in f.iter().enumerate() {
            let v = self.stepped_velocity(i, *f, dt);
            self.velocities[i] = v;
            self.positions[i] += dt * v;
        }
        self.scratch = f;
        self.time += dt;
    }

    /// One explicit step of `dt` for `nodes` only; every other node is frozen in place
    /// (PHYSICS.md §2.5) and acts on them through its springs.
    pub fn step_nodes(&mut self, dt: f64, nodes: &[u32]) {
        let mut f = std::mem::take(&mut self.scratch);
        self.gather_forces(nodes, &mut f);
        self.integrate_nodes(dt, nodes, &f);
        self.scratch = f;
    }

    /// Simulate `duration` seconds in equal steps no larger than the stable step; returns
    /// the number of steps taken.
    pub fn advance(&mut self, duration: f64) -> u32 {
        if duration <= 0.0 {
            return 0;
        }
        let steps = (duration / self.stable_dt).ceil().max(1.0) as u32;
        let dt = duration / steps as f64;
        for _ in 0..steps {
            self.step(dt);
        }
        steps
    }

    /// Zero the velocity of every node (e.g. a node leaving the free set).
    pub fn stop_nodes(&mut self, nodes: &[u32]) {
        for &i in nodes {
            self.velocities[i as usize] = DVec3::ZERO;
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;
    use crate::mass_spring::{AxisMask, MassSpringParams, Tension};
    use crate::mesh::TetMesh;

    fn cube(params: MassSpringParams) -> MassSpringModel {
        let (mesh, _) =
            TetMesh::from_raw(block(Vec3::ZERO, Vec3::splat(0.02), UVec3::new(2, 2, 2))).unwrap();
        MassSpringModel::new(&mesh, params).unwrap()
    }

    #[test]
    fn untensioned_model_without_gravity_stays_at_rest() {
        let mut m = cube(MassSpringParams {
            gravity: DVec3::ZERO,
            ..MassSpringParams::default()
        });
        let x0 = m.positions().to_vec();
        m.advance(0.05);
        for (a, b) in x0.iter().zip(m.positions()) {
            assert!((*a - *b).length() < 1e-15);
        }
    }

    #[test]
    fn tensioned_free_cube_shrinks_to_one_minus_s() {
        // With no node held, the rest state of l = d(1 − s) is the body scaled by (1 − s).
        let mut m = cube(MassSpringParams {
            gravity: DVec3::ZERO,
            tension: Tension::Uniform(0.1),
            ..MassSpringParams::default()
        });
        m.advance(1.0);
        let (lo, hi) = m
            .positions()
            .iter()
            .fold((DVec3::MAX, DVec3::MIN), |(a, b), p| (a.min(*p), b.max(*p)));
        let size = hi - lo;
        for c in size.to_array() {
            assert!((c - 0.018).abs() < 2e-6, "{size}");
        }
        assert!(m.kinetic_energy() < 1e-12);
    }

    #[test]
    fn hanging_cube_settles_where_springs_carry_its_weight() {
        // Top face pinned: the cube sags under gravity, and the spring forces at the pinned
        // nodes carry the weight of the free nodes.
        let mut m = cube(MassSpringParams::default());
        let top: Vec<u32> = (0..m.node_count() as u32)
            .filter(|&i| m.positions()[i as usize].z > 0.0199)
            .collect();
        m.fix(&top, AxisMask::ALL).unwrap();
        m.advance(2.0);
        let free_weight: f64 = (0..m.node_count())
            .filter(|i| !top.contains(&(*i as u32)))
            .map(|i| m.masses()[i] * 9.81)
            .sum();
        let held: f64 = top.iter().map(|&i| m.spring_force(i as usize).z).sum();
        assert!(m.positions().iter().all(|p| p.z <= 0.0200001));
        assert!(
            ((-held) - free_weight).abs() < 1e-6 * free_weight,
            "{held} vs {free_weight}"
        );
    }
}
