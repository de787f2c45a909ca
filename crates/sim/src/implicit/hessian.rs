//! The Hessian of the implicit step's `G` applied matrix-free: the tets' evaluations at an
//! iterate (forces, diagonal blocks, energies, stress tangents), `G` and its gradient
//! gathered per node, and the product `∇²G p` tet by tet ([`super::TetTangent`]) summed
//! per node in fixed parts ([`ProductParts`]).

use glam::{Mat3, Vec3, Vec3A};

use super::product_parts::ProductParts;
use super::rest_tet::RestTet;
use super::tet_evals::{Iterate, MIN_PART, TetEvals, active_chunks, for_each};
use crate::material::Lame;
use crate::thread_team::{ThreadTeam, for_each_zip2};
use crate::xpbd::lanes::LANES;

/// The Hessian of `G` applied matrix-free.
pub(super) struct Hessian {
    /// Every tet's nodes, `Dm⁻¹` and rest volume, in mesh order.
    pub(super) tets: Vec<RestTet>,
    /// Every tet's shape gradients `b_a`.
    pub(super) b: Vec<[Vec3; 4]>,
    /// Where each node's (tet, corner) pairs start in `inc` (one more than the nodes).
    pub(super) inc_offsets: Vec<u32>,
    /// The (tet, corner) pairs of every node, node by node.
    pub(super) inc: Vec<(u32, u8)>,
    /// Lumped node masses, kg.
    pub(super) mass: Vec<f32>,
    /// `1/h²` of the step, 1/s².
    pub(super) inv_h2: f32,
    /// The material's Lamé parameters.
    pub(super) lame: Lame,
    /// The tets' evaluations, in chunks of eight for the SIMD kernels or tet by tet
    /// (the reference).
    pub(super) evals: TetEvals,
    /// The tets' product forces summed per node, one vector per fixed range of tets.
    pub(super) product_parts: ProductParts,
    /// The chunks of eight tets whose forces reach a free node (found once a step).
    pub(super) active: Vec<u32>,
    /// Per chunk, whether none of its tets reaches a free node (empty: none known).
    pub(super) fixed: Vec<bool>,
}

impl Hessian {
    /// Forces, diagonal blocks, tangents and energy of every live tet at `u` (but those of
    /// the chunks [`Hessian::find_active`] found fixed, whose values at the step's start
    /// hold: their nodes do not move); returns `G(u)`.
    pub(super) fn evaluate(
        &mut self,
        u: &[Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        team: Option<&ThreadTeam>,
    ) -> f64 {
        self.evaluate_parts(u, y, (live, free), team, true)
    }

    /// `G(u)` alone: only the tets' energies are updated (their forces, diagonal blocks
    /// and tangents stay those of the last [`Hessian::evaluate`]); the same value
    /// `evaluate` returns, to the bit.
    pub(super) fn energy(
        &mut self,
        u: &[Vec3],
        y: &[Vec3],
        live: &[bool],
        free: &[bool],
        team: Option<&ThreadTeam>,
    ) -> f64 {
        self.evaluate_parts(u, y, (live, free), team, false)
    }

    /// `G(u)` after evaluating the tets at `u`: everything (`full`) or their energies.
    fn evaluate_parts(
        &mut self,
        u: &[Vec3],
        y: &[Vec3],
        (live, free): (&[bool], &[bool]),
        team: Option<&ThreadTeam>,
        full: bool,
    ) -> f64 {
        let at = Iterate {
            u,
            live,
            lame: self.lame,
            b: &self.b,
            team,
        };
        self.evals.evaluate(&self.tets, at, full, &self.fixed);
        self.total(u, y, free)
    }

    /// `G` from the tets' energies and the inertia at `u`.
    pub(super) fn total(&self, u: &[Vec3], y: &[Vec3], free: &[bool]) -> f64 {
        let elastic = self.evals.elastic_energy();
        let inertia: f64 = (0..u.len())
            .filter(|&i| free[i])
            .map(|i| (self.mass[i] * (u[i] - y[i]).length_squared()) as f64)
            .sum();
        elastic + 0.5 * self.inv_h2 as f64 * inertia
    }

    /// `∂G/∂x` and the diagonal block of `∇²G` at node `i` from the tet evaluations in
    /// hand: `m/h² (u − y)` and `m/h² I` plus its tets' corner forces and blocks.
    pub(super) fn node_sums(&self, u: &[Vec3], y: &[Vec3], i: usize) -> (Vec3, Mat3) {
        let m = self.mass[i] * self.inv_h2;
        let mut g = (u[i] - y[i]) * m;
        let mut d = Mat3::IDENTITY * m;
        for &(t, a) in self.incident(i) {
            g += self.evals.force(t as usize, a as usize);
            d += self.evals.diag(t as usize, a as usize);
        }
        (g, d)
    }

    /// `∇G` and the inverted diagonal blocks of `∇²G` per node (zero at fixed nodes).
    pub(super) fn gather_gradient(
        &self,
        u: &[Vec3],
        y: &[Vec3],
        free: &[bool],
        gradient: &mut [Vec3],
        diag_inv: &mut [Mat3],
        team: Option<&ThreadTeam>,
    ) {
        let node = |i: usize, g: &mut Vec3, d_inv: &mut Mat3| {
            (*g, *d_inv) = if free[i] {
                let (g, d) = self.node_sums(u, y, i);
                (g, d.inverse())
            } else {
                (Vec3::ZERO, Mat3::ZERO)
            };
        };
        for_each_zip2(team, (gradient, diag_inv), MIN_PART, node);
    }

    /// Find the chunks of tets whose forces reach a free node (what [`Hessian::apply`]
    /// sums): once a step, as `live` and `free` change only between steps.
    pub(super) fn find_active(&mut self, live: &[bool], free: &[bool]) {
        self.active = active_chunks(&self.tets, live, free);
        let nodes = self.mass.len();
        self.product_parts
            .set_chunks(&self.tets, &self.active, nodes);
        self.fixed.clear();
        self.fixed.resize(self.tets.len().div_ceil(LANES), true);
        for &c in &self.active {
            self.fixed[c as usize] = false;
        }
    }

    /// `out = ∇²G p` (zero at fixed nodes; the chunks of [`Hessian::find_active`]).
    pub(super) fn apply(
        &mut self,
        p: &[Vec3],
        out: &mut [Vec3],
        live: &[bool],
        free: &[bool],
        team: Option<&ThreadTeam>,
    ) {
        let at = Iterate {
            u: p,
            live,
            lame: self.lame,
            b: &self.b,
            team,
        };
        let active = &self.active;
        self.evals
            .products(&self.tets, at, active, &mut self.product_parts);
        self.gather_products(p, out, free, team);
    }

    /// `out = M/h² p +` the tets' forces at each free node, the parts added in order
    /// (zero at fixed nodes).
    pub(super) fn gather_products(
        &self,
        p: &[Vec3],
        out: &mut [Vec3],
        free: &[bool],
        team: Option<&ThreadTeam>,
    ) {
        let (parts, mass, inv_h2) = (&self.product_parts, &self.mass, self.inv_h2);
        let node = |i: usize, o: &mut Vec3| {
            if !free[i] {
                *o = Vec3::ZERO;
                return;
            }
            let inertia = Vec3A::from(p[i] * (mass[i] * inv_h2));
            *o = parts.add_at(i, inertia).into();
        };
        for_each(team, out, node);
    }

    /// The (tet, corner) pairs of node `i`.
    pub(super) fn incident(&self, i: usize) -> &[(u32, u8)] {
        &self.inc[self.inc_offsets[i] as usize..self.inc_offsets[i + 1] as usize]
    }
}
