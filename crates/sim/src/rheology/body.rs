//! A tet mesh whose every edge is a three-element element, integrated with classical RK4
//! over node positions, node velocities and the edges' Voigt ratios (PHYSICS.md §3).

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::{EdgeList, TetMesh};

use super::edge_law::EdgeLaw;
use super::error::RheologyError;
use super::indenter::FlatIndenter;
use super::material::RheologyMaterial;
use super::regions::MaterialMap;
use super::rk4::Rk4;
use super::stability::{StabilityLimit, stability_limit};

/// Edge count from which the force passes run on the rayon pool.
const PARALLEL_EDGES: usize = 20_000;

/// A rheological body: nodes with lumped masses, edges with three-element elements.
///
/// State layout (one flat vector for RK4): positions `x` (3n), velocities `v` (3n), Voigt
/// ratios `a` (one per edge).
#[derive(Debug, Clone)]
pub struct RheologyBody {
    edges: EdgeList,
    /// The materials; edge `e` takes `materials[map.edge_material[e]]`.
    materials: Vec<RheologyMaterial>,
    /// Each material's element law with its constants folded (the force pass's view).
    laws: Vec<EdgeLaw>,
    map: MaterialMap,
    /// Rest length L0 of every edge (f64, from the rest positions), m.
    rest_length: Vec<f64>,
    masses: Vec<f64>,
    pinned: Vec<bool>,
    gravity: DVec3,
    indenter: Option<FlatIndenter>,
    pub(super) state: Vec<f64>,
    pub(super) time: f64,
    limit: StabilityLimit,
    rk4: Rk4,
    edge_force: Vec<DVec3>,
}

/// What the force passes read: the constant part of a body.
///
/// Element constants are made per edge and stage from the material's folded law and the
/// rest length (a few multiplications) rather than stored: 12 bytes read per edge instead
/// of ~90 keeps a plate-sized body in cache.
struct Forces<'a> {
    edges: &'a EdgeList,
    laws: &'a [EdgeLaw],
    edge_material: &'a [u32],
    rest_length: &'a [f64],
    masses: &'a [f64],
    pinned: &'a [bool],
    gravity: DVec3,
}

impl RheologyBody {
    /// A body of one material at rest in `mesh`'s rest shape.
    pub fn uniform(mesh: &TetMesh, material: RheologyMaterial) -> Result<Self, RheologyError> {
        let edges = EdgeList::of_mesh(mesh);
        let map = MaterialMap::uniform(mesh, &edges);
        Self::with_edges(mesh, edges, &[material], map)
    }

    /// A body at rest with material `materials[map.tet_material[t]]` per tet (density) and
    /// `materials[map.edge_material[e]]` per edge (element constants).
    pub fn new(
        mesh: &TetMesh,
        materials: &[RheologyMaterial],
        map: MaterialMap,
    ) -> Result<Self, RheologyError> {
        Self::with_edges(mesh, EdgeList::of_mesh(mesh), materials, map)
    }

    fn with_edges(
        mesh: &TetMesh,
        edges: EdgeList,
        materials: &[RheologyMaterial],
        map: MaterialMap,
    ) -> Result<Self, RheologyError> {
        for (i, m) in materials.iter().enumerate() {
            if let Some((field, message)) = m.problem() {
                return Err(RheologyError::BadMaterial {
                    material: format!("#{i}"),
                    field: field.into(),
                    message,
                });
            }
        }
        let count = materials.len();
        if let Some(&bad) = map
            .tet_material
            .iter()
            .chain(&map.edge_material)
            .find(|&&m| m as usize >= count)
        {
            return Err(RheologyError::MaterialIndex {
                index: bad as usize,
                count,
            });
        }
        let densities: Vec<f64> = materials.iter().map(|m| m.density).collect();
        let masses = map.node_masses(mesh, &densities);
        let n = mesh.node_count();
        let mut state = vec![0.0; 6 * n + edges.len()];
        for (i, p) in mesh.rest_positions.iter().enumerate() {
            p.as_dvec3().write_to_slice(&mut state[3 * i..3 * i + 3]);
        }
        let mut rest_length = Vec::with_capacity(edges.len());
        for (e, &[i, j]) in edges.edges.iter().enumerate() {
            // Rest length in f64 from the rest positions (EdgeList keeps f32).
            rest_length.push(
                (mesh.rest_positions[j as usize].as_dvec3()
                    - mesh.rest_positions[i as usize].as_dvec3())
                .length(),
            );
            state[6 * n + e] = materials[map.edge_material[e] as usize].rest_ratio;
        }
        let materials = materials.to_vec();
        let laws = materials.iter().map(EdgeLaw::of).collect();
        let pinned = vec![false; n];
        let limit = stability_limit(
            &edges.edges,
            |e| materials[map.edge_material[e] as usize].element(rest_length[e]),
            &masses,
            &pinned,
        );
        let len = state.len();
        let edge_count = edges.len();
        Ok(RheologyBody {
            edges,
            materials,
            laws,
            map,
            rest_length,
            masses,
            pinned,
            gravity: DVec3::ZERO,
            indenter: None,
            state,
            time: 0.0,
            limit,
            rk4: Rk4::new(len),
            edge_force: vec![DVec3::ZERO; edge_count],
        })
    }

    /// Fix `nodes` in place (their velocity is zero from now on).
    pub fn pin(&mut self, nodes: &[u32]) {
        let n = self.node_count();
        for &i in nodes {
            self.pinned[i as usize] = true;
            self.state[3 * n + 3 * i as usize..3 * n + 3 * i as usize + 3].fill(0.0);
        }
        self.update_limit();
    }

    /// Uniform gravitational acceleration, m/s².
    pub fn set_gravity(&mut self, g: DVec3) {
        self.gravity = g;
    }

    /// Press with `indenter` (or stop pressing with `None`).
    pub fn set_indenter(&mut self, indenter: Option<FlatIndenter>) {
        self.indenter = indenter;
    }

    /// Set node `i`'s velocity (m/s); ignored for pinned nodes.
    pub fn set_velocity(&mut self, i: usize, v: DVec3) {
        if !self.pinned[i] {
            let n = self.node_count();
            v.write_to_slice(&mut self.state[3 * n + 3 * i..3 * n + 3 * i + 3]);
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.masses.len()
    }

    /// The body's edges.
    pub fn edges(&self) -> &EdgeList {
        &self.edges
    }

    /// Lumped node masses, kg.
    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    /// Material index of every tet and edge.
    pub fn material_map(&self) -> &MaterialMap {
        &self.map
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Position of node `i`, m.
    pub fn position(&self, i: usize) -> DVec3 {
        DVec3::from_slice(&self.state[3 * i..3 * i + 3])
    }

    /// Velocity of node `i`, m/s.
    pub fn velocity(&self, i: usize) -> DVec3 {
        let n = self.node_count();
        DVec3::from_slice(&self.state[3 * n + 3 * i..3 * n + 3 * i + 3])
    }

    /// All node positions, m.
    pub fn positions(&self) -> Vec<DVec3> {
        (0..self.node_count()).map(|i| self.position(i)).collect()
    }

    /// Voigt ratio `a` of every edge.
    pub fn ratios(&self) -> &[f64] {
        &self.state[6 * self.node_count()..]
    }

    /// Clamp bounds (a_min, a_max) of edge `e`.
    pub fn ratio_bounds(&self, e: usize) -> (f64, f64) {
        let m = &self.materials[self.map.edge_material[e] as usize];
        (m.ratio_min, m.ratio_max)
    }

    /// The explicit RK4 stability limit for the current pins.
    pub fn stability(&self) -> StabilityLimit {
        self.limit
    }

    /// Kinetic energy `Σ ½ m v²`, J.
    pub fn kinetic_energy(&self) -> f64 {
        (0..self.node_count())
            .map(|i| 0.5 * self.masses[i] * self.velocity(i).length_squared())
            .sum()
    }

    /// Energy stored in the Voigt springs `Σ ½k(aL − l)²`, J.
    pub fn stored_energy(&self) -> f64 {
        let ratios = self.ratios();
        (0..self.edges.len())
            .map(|e| {
                let [i, j] = self.edges.edges[e];
                let len = (self.position(j as usize) - self.position(i as usize)).length();
                let m = &self.materials[self.map.edge_material[e] as usize];
                let l0 = self.rest_length[e];
                m.element(l0)
                    .stored_energy(m.rest_ratio * l0, len, ratios[e])
            })
            .sum()
    }

    /// Potential energy in the gravity field, `−Σ m g·x`, J.
    pub fn gravity_energy(&self) -> f64 {
        (0..self.node_count())
            .map(|i| -self.masses[i] * self.gravity.dot(self.position(i)))
            .sum()
    }

    /// Advance by `dt` in equal substeps at or below the safe step; returns their count.
    pub fn advance(&mut self, dt: f64) -> Result<usize, RheologyError> {
        let substeps = (dt / self.limit.safe_step()).ceil().max(1.0) as usize;
        let h = dt / substeps as f64;
        for _ in 0..substeps {
            self.step(h)?;
        }
        Ok(substeps)
    }

    /// One RK4 step of `h` seconds; an error above the stability limit or on divergence.
    pub fn step(&mut self, h: f64) -> Result<(), RheologyError> {
        if !(h > 0.0 && h <= self.limit.max_step) {
            return Err(RheologyError::StepTooLarge {
                step: h,
                limit: self.limit.max_step,
            });
        }
        let forces = Forces {
            edges: &self.edges,
            laws: &self.laws,
            edge_material: &self.map.edge_material,
            rest_length: &self.rest_length,
            masses: &self.masses,
            pinned: &self.pinned,
            gravity: self.gravity,
        };
        let edge_force = &mut self.edge_force;
        self.rk4.step(&mut self.state, self.time, h, |_, y, dy| {
            forces.rates(y, dy, edge_force)
        });
        self.time += h;
        let n = self.masses.len();
        // PHYSICS.md §3, eqs. (4), (5): clamp the ratios after each step.
        let (xv, ratios) = self.state.split_at_mut(6 * n);
        for (a, &m) in ratios.iter_mut().zip(&self.map.edge_material) {
            let m = &self.materials[m as usize];
            *a = a.clamp(m.ratio_min, m.ratio_max);
        }
        if let Some(ind) = &self.indenter {
            let (x, v) = xv.split_at_mut(3 * n);
            ind.apply(self.time, x, v);
        }
        // A NaN or infinity anywhere reaches the positions within the step (through the
        // velocity stages), so a sum over them detects divergence in one vectorised pass.
        if !self.state[..3 * n].iter().sum::<f64>().is_finite() {
            return Err(RheologyError::Diverged { time: self.time });
        }
        Ok(())
    }

    fn update_limit(&mut self) {
        let (materials, map, rest) = (&self.materials, &self.map, &self.rest_length);
        self.limit = stability_limit(
            &self.edges.edges,
            |e| materials[map.edge_material[e] as usize].element(rest[e]),
            &self.masses,
            &self.pinned,
        );
    }
}

impl Forces<'_> {
    /// `dy = (v, F/m, ȧ)` for state `y`; `edge_force` is scratch (one vector per edge).
    fn rates(&self, y: &[f64], dy: &mut [f64], edge_force: &mut [DVec3]) {
        let n = self.masses.len();
        let (x, v) = (&y[..3 * n], &y[3 * n..6 * n]);
        let ratios = &y[6 * n..];
        let (dxv, ratio_rates) = dy.split_at_mut(6 * n);
        // Edge pass: tension along each edge (force on its first node) and ȧ.
        let edge = |e: usize, force: &mut DVec3, rate: &mut f64| {
            let [i, j] = self.edges.edges[e];
            let (i, j) = (3 * i as usize, 3 * j as usize);
            let d = DVec3::from_slice(&x[j..j + 3]) - DVec3::from_slice(&x[i..i + 3]);
            let len = d.length();
            let inv_len = 1.0 / len;
            let dir = d * inv_len;
            let len_rate =
                (DVec3::from_slice(&v[j..j + 3]) - DVec3::from_slice(&v[i..i + 3])).dot(dir);
            let law = &self.laws[self.edge_material[e] as usize];
            let (tension, ratio_rate) =
                law.respond(self.rest_length[e], len, inv_len, len_rate, ratios[e]);
            *force = dir * tension;
            *rate = ratio_rate;
        };
        // Node pass: sum the edge forces (fixed order: deterministic in parallel too).
        let node = |i: usize, edge_force: &[DVec3], dx: &mut [f64], dv: &mut [f64]| {
            if self.pinned[i] {
                dx.fill(0.0);
                dv.fill(0.0);
                return;
            }
            let mut f = self.gravity * self.masses[i];
            for &e in self.edges.edges_of_node(i) {
                let e = e as usize;
                if self.edges.edges[e][0] as usize == i {
                    f += edge_force[e];
                } else {
                    f -= edge_force[e];
                }
            }
            dx.copy_from_slice(&v[3 * i..3 * i + 3]);
            (f / self.masses[i]).write_to_slice(dv);
        };
        if self.edges.len() >= PARALLEL_EDGES {
            edge_force
                .par_iter_mut()
                .zip(ratio_rates.par_iter_mut())
                .enumerate()
                .for_each(|(e, (f, r))| edge(e, f, r));
            let edge_force = &*edge_force;
            let (dx, dv) = dxv.split_at_mut(3 * n);
            dx.par_chunks_mut(3)
                .zip(dv.par_chunks_mut(3))
                .enumerate()
                .for_each(|(i, (dx, dv))| node(i, edge_force, dx, dv));
        } else {
            for (e, (f, r)) in edge_force
                .iter_mut()
                .zip(ratio_rates.iter_mut())
                .enumerate()
            {
                edge(e, f, r);
            }
            let (dx, dv) = dxv.split_at_mut(3 * n);
            for (i, (dx, dv)) in dx.chunks_mut(3).zip(dv.chunks_mut(3)).enumerate() {
                node(i, edge_force, dx, dv);
            }
        }
    }
}
