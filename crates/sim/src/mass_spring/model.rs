//! The mass-spring model over a tet mesh (PHYSICS.md §2.1): nodes with reference and
//! current positions, tets that carry mass, and one spring per tet edge.
//!
//! Springs are stored per node (each spring twice, once at each end) so that a cut can
//! rebuild them locally and the integrator can gather forces for any subset of nodes.
//! A spring's rest length is a function of its ends' *reference* positions (eq. 3), so
//! moving a node in the reference configuration updates its rest lengths.

use glam::DVec3;

use super::{AxisMask, MassSpringError, MassSpringParams, StiffnessLaw, TetTensor, edge_frames};
use crate::mesh::{TET_EDGES, TetMesh};

/// One end's view of a spring: the node at the other end, the rest length and the
/// spring constant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// Node at the other end.
    pub node: u32,
    /// Rest length `l0`, m.
    pub rest: f64,
    /// Spring constant `k` of this edge, N/m ([`crate::mass_spring::StiffnessLaw`]).
    pub stiffness: f64,
}

/// Nodes, tets and springs of the mass-spring model, and its dynamic state.
#[derive(Debug, Clone)]
pub struct MassSpringModel {
    pub(crate) params: MassSpringParams,
    /// Reference (initial, unstrained-layout) positions; rest lengths derive from these.
    pub(crate) reference: Vec<DVec3>,
    pub(crate) positions: Vec<DVec3>,
    pub(crate) velocities: Vec<DVec3>,
    pub(crate) masses: Vec<f64>,
    pub(crate) fixed: Vec<AxisMask>,
    pub(crate) tets: Vec<[u32; 4]>,
    /// Mass carried by each tet (ρ V at creation, split by volume on subdivision).
    pub(crate) tet_mass: Vec<f64>,
    /// Bit `f` set: the face opposite local vertex `f` is cut surface.
    pub(crate) tet_cut_faces: Vec<u8>,
    pub(crate) node_tets: Vec<Vec<u32>>,
    pub(crate) springs: Vec<Vec<Spring>>,
    /// Node pairs created by duplication at a cut (original, copy).
    pub(crate) twins: Vec<[u32; 2]>,
    pub(crate) time: f64,
    pub(crate) stable_dt: f64,
    /// Per-step scratch buffer of the integrator.
    pub(crate) scratch: Vec<DVec3>,
    /// External forces on single nodes (a tool), N.
    pub(crate) external: Vec<(u32, DVec3)>,
    initial_mass: f64,
    /// Scale `c` of the stiffness law, fixed on the uncut mesh.
    stiffness_scale: f64,
    /// Each tet's share of the constant of its six edges ([`TET_EDGES`] order), N/m
    /// (`TetVolume` law; an edge's constant is the sum over its tets).
    pub(crate) tet_k: Vec<[f64; 6]>,
    /// The stiffness per unit volume each tet carries (kept through splits and moves).
    pub(crate) tet_material: Vec<TetTensor>,
}

impl MassSpringModel {
    /// A model over `mesh` at its rest positions (which are the reference positions: with
    /// tension, the model starts strained and held by its fixed nodes).
    pub fn new(mesh: &TetMesh, params: MassSpringParams) -> Result<Self, MassSpringError> {
        params.validate()?;
        let reference: Vec<DVec3> = mesh.rest_positions.iter().map(|p| p.as_dvec3()).collect();
        let n = reference.len();
        let mut tet_mass = Vec::with_capacity(mesh.tet_count());
        for (t, tet) in mesh.tets.iter().enumerate() {
            let volume = signed_volume(tet.map(|i| reference[i as usize]));
            if volume.is_nan() || volume <= 0.0 {
                return Err(MassSpringError::BadTet { tet: t, volume });
            }
            tet_mass.push(params.density * volume);
        }
        let mut node_tets = vec![Vec::new(); n];
        for (t, tet) in mesh.tets.iter().enumerate() {
            for &v in tet {
                node_tets[v as usize].push(t as u32);
            }
        }
        let (scale, tet_k, tet_material) = initial_stiffness(&params, &reference, &mesh.tets);
        let mut model = MassSpringModel {
            params,
            positions: reference.clone(),
            velocities: vec![DVec3::ZERO; n],
            masses: vec![0.0; n],
            fixed: vec![AxisMask::NONE; n],
            tets: mesh.tets.clone(),
            tet_cut_faces: vec![0; mesh.tet_count()],
            tet_mass,
            node_tets,
            springs: vec![Vec::new(); n],
            tet_k,
            tet_material,
            twins: Vec::new(),
            reference,
            time: 0.0,
            stable_dt: 0.0,
            scratch: Vec::new(),
            external: Vec::new(),
            initial_mass: 0.0,
            stiffness_scale: scale,
        };
        let all: Vec<u32> = (0..n as u32).collect();
        for v in 0..n as u32 {
            model.springs[v as usize] = model.springs_from_tets(v);
        }
        model.recompute_masses(&all);
        model.initial_mass = model.tet_mass.iter().sum();
        model.refresh_stability();
        Ok(model)
    }

    /// The parameters in use.
    pub fn params(&self) -> &MassSpringParams {
        &self.params
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of tets.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// Number of springs (unique tet edges).
    pub fn edge_count(&self) -> usize {
        self.springs.iter().map(Vec::len).sum::<usize>() / 2
    }

    /// Current positions, m.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Reference positions (the initial layout that rest lengths are measured in), m.
    pub fn reference_positions(&self) -> &[DVec3] {
        &self.reference
    }

    /// Node velocities, m/s.
    pub fn velocities(&self) -> &[DVec3] {
        &self.velocities
    }

    /// Node masses from eq. 4, kg.
    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    /// Tet connectivity (positively oriented in the reference configuration).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Mass carried by each tet, kg.
    pub fn tet_masses(&self) -> &[f64] {
        &self.tet_mass
    }

    /// Per tet, bit `f` set when the face opposite local vertex `f` is cut surface.
    pub fn tet_cut_faces(&self) -> &[u8] {
        &self.tet_cut_faces
    }

    /// Tets incident to node `i`.
    pub fn tets_of(&self, i: usize) -> &[u32] {
        &self.node_tets[i]
    }

    /// Springs at node `i`.
    pub fn springs_of(&self, i: usize) -> &[Spring] {
        &self.springs[i]
    }

    /// Axes along which node `i` is held.
    pub fn fixed_axes(&self, i: usize) -> AxisMask {
        self.fixed[i]
    }

    /// Node pairs (original, copy) that a cut separated.
    pub fn twins(&self) -> &[[u32; 2]] {
        &self.twins
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Total mass when the model was built, kg.
    pub fn initial_mass(&self) -> f64 {
        self.initial_mass
    }

    /// Sum of the node masses, kg.
    pub fn total_mass(&self) -> f64 {
        self.masses.iter().sum()
    }

    /// Hold `nodes` along `axes` (added to what they already hold); their velocity along
    /// those axes is zeroed.
    pub fn fix(&mut self, nodes: &[u32], axes: AxisMask) -> Result<(), MassSpringError> {
        let count = self.node_count();
        if let Some(&index) = nodes.iter().find(|&&i| i as usize >= count) {
            return Err(MassSpringError::NodeOutOfRange { index, count });
        }
        for &i in nodes {
            let m = self.fixed[i as usize].union(axes);
            self.fixed[i as usize] = m;
            self.velocities[i as usize] = m.free_part(self.velocities[i as usize]);
        }
        Ok(())
    }

    /// Set the current position of node `i` (a scripted or haptic handle), m.
    pub fn set_position(&mut self, i: usize, p: DVec3) {
        self.positions[i] = p;
    }

    /// Apply an external force `f` (N) to node `i` in every step until cleared.
    pub fn set_external_force(&mut self, i: u32, f: DVec3) {
        match self.external.iter_mut().find(|(n, _)| *n == i) {
            Some(e) => e.1 = f,
            None => self.external.push((i, f)),
        }
    }

    /// Remove every external force.
    pub fn clear_external_forces(&mut self) {
        self.external.clear();
    }

    /// Kinetic energy ½ Σ m v², J.
    pub fn kinetic_energy(&self) -> f64 {
        self.masses
            .iter()
            .zip(&self.velocities)
            .map(|(m, v)| 0.5 * m * v.length_squared())
            .sum()
    }

    /// Reference volume of tet `t`, m³ (signed; positive for a valid tet).
    pub fn reference_volume(&self, t: usize) -> f64 {
        signed_volume(self.tets[t].map(|i| self.reference[i as usize]))
    }

    /// Current volume of tet `t`, m³ (signed).
    pub fn current_volume(&self, t: usize) -> f64 {
        signed_volume(self.tets[t].map(|i| self.positions[i as usize]))
    }

    /// Index of the node whose current position is nearest to `p`.
    pub fn nearest_node(&self, p: DVec3) -> Option<u32> {
        self.positions
            .iter()
            .enumerate()
            .min_by(|a, b| {
                (*a.1 - p)
                    .length_squared()
                    .total_cmp(&(*b.1 - p).length_squared())
            })
            .map(|(i, _)| i as u32)
    }

    // ---- topology edits used by the cutter -------------------------------------------

    /// Append a node; it has no tets (and so no mass) until tets reference it.
    pub(crate) fn add_node(
        &mut self,
        reference: DVec3,
        position: DVec3,
        velocity: DVec3,
        fixed: AxisMask,
    ) -> u32 {
        self.reference.push(reference);
        self.positions.push(position);
        self.velocities.push(fixed.free_part(velocity));
        self.masses.push(0.0);
        self.fixed.push(fixed);
        self.node_tets.push(Vec::new());
        self.springs.push(Vec::new());
        (self.positions.len() - 1) as u32
    }

    /// Replace the vertices of tet `t`, keeping node→tet adjacency in step.
    pub(crate) fn set_tet(&mut self, t: u32, tet: [u32; 4]) {
        let old = self.tets[t as usize];
        for v in old {
            if !tet.contains(&v) {
                let list = &mut self.node_tets[v as usize];
                if let Some(k) = list.iter().position(|&x| x == t) {
                    list.swap_remove(k);
                }
            }
        }
        for v in tet {
            if !old.contains(&v) {
                self.node_tets[v as usize].push(t);
            }
        }
        self.tets[t as usize] = tet;
    }

    /// Append a tet carrying `mass` and the stiffness `material` (per unit volume) with
    /// cut-face flags `cut_faces`; its spring shares are fitted at the next rebuild.
    pub(crate) fn push_tet(
        &mut self,
        tet: [u32; 4],
        mass: f64,
        material: TetTensor,
        cut_faces: u8,
    ) -> u32 {
        let t = self.tets.len() as u32;
        self.tets.push(tet);
        self.tet_k.push([0.0; 6]);
        self.tet_material.push(material);
        self.tet_mass.push(mass);
        self.tet_cut_faces.push(cut_faces);
        for v in tet {
            self.node_tets[v as usize].push(t);
        }
        t
    }

    /// Move node `i` by `d` in both the reference and the current configuration.
    pub(crate) fn displace(&mut self, i: usize, d: DVec3) {
        self.reference[i] += d;
        self.positions[i] += d;
    }

    /// Recompute the masses of `nodes` from their tets (eq. 4).
    // PHYSICS.md §2.3, eq. 4: m_i = Σ_{k ∈ E(i)} ρ_k V_k / 4 (ρ_k V_k = the tet's mass).
    pub(crate) fn recompute_masses(&mut self, nodes: &[u32]) {
        for &i in nodes {
            self.masses[i as usize] = self.node_tets[i as usize]
                .iter()
                .map(|&t| 0.25 * self.tet_mass[t as usize])
                .sum();
        }
    }

    /// Rebuild the springs of `affected` nodes from their tets (rest lengths from eq. 3,
    /// constants from the stiffness law), and refresh what their unaffected neighbours
    /// store for them.
    ///
    /// A node whose tets did not change keeps its neighbour set, so only nodes whose tets
    /// changed, or that moved, need to be listed.
    pub(crate) fn rebuild_springs(&mut self, affected: &[u32]) {
        if self.params.stiffness_law == StiffnessLaw::TetVolume {
            let mut tets: Vec<u32> = affected
                .iter()
                .flat_map(|&v| self.node_tets[v as usize].iter().copied())
                .collect();
            tets.sort_unstable();
            tets.dedup();
            for t in tets {
                self.refit_tet(t as usize);
            }
        }
        let mut is_affected = vec![false; self.node_count()];
        for &v in affected {
            is_affected[v as usize] = true;
        }
        for &v in affected {
            let vi = v as usize;
            self.springs[vi] = self.springs_from_tets(v);
            for k in 0..self.springs[vi].len() {
                let s = self.springs[vi][k];
                if is_affected[s.node as usize] {
                    continue;
                }
                if let Some(back) = self.springs[s.node as usize]
                    .iter_mut()
                    .find(|b| b.node == v)
                {
                    back.rest = s.rest;
                    back.stiffness = s.stiffness;
                }
            }
        }
    }

    /// Refit tet `t`'s spring shares to its stiffness per unit volume on its present
    /// reference shape (after a split or a node move).
    // docs/physics-notes.md, "Nakao": the tet keeps the material it carried.
    fn refit_tet(&mut self, t: usize) {
        let p = self.tets[t].map(|i| self.reference[i as usize]);
        let frames = edge_frames(p);
        self.tet_k[t] = self.tet_material[t].fit(&frames, signed_volume(p), self.tet_k[t]);
    }

    /// The springs of node `v` from its tets. Each edge's shares are summed in tet order,
    /// so both ends compute the same constant.
    fn springs_from_tets(&self, v: u32) -> Vec<Spring> {
        let mut pairs: Vec<(u32, u32, f64)> = Vec::new();
        for &t in &self.node_tets[v as usize] {
            let tet = self.tets[t as usize];
            for (e, (i, j)) in TET_EDGES.iter().enumerate() {
                let w = match (tet[*i] == v, tet[*j] == v) {
                    (true, _) => tet[*j],
                    (_, true) => tet[*i],
                    _ => continue,
                };
                pairs.push((w, t, self.tet_k[t as usize][e]));
            }
        }
        pairs.sort_unstable_by_key(|a| (a.0, a.1));
        let (tension, law, k) = (
            self.params.tension,
            self.params.stiffness_law,
            self.params.stiffness,
        );
        let x = &self.reference;
        let mut out: Vec<Spring> = Vec::new();
        let mut share = 0.0;
        for (i, &(w, _, k_t)) in pairs.iter().enumerate() {
            share += k_t;
            if pairs.get(i + 1).is_some_and(|n| n.0 == w) {
                continue;
            }
            let (a, b) = (v.min(w) as usize, v.max(w) as usize);
            out.push(Spring {
                node: w,
                rest: tension.rest_length(x[a], x[b]),
                stiffness: match law {
                    StiffnessLaw::Uniform => k,
                    StiffnessLaw::TetVolume => share,
                },
            });
            share = 0.0;
        }
        out
    }

    /// The stiffness law's scale `c`, fixed on the uncut mesh (1 for `Uniform`).
    pub fn stiffness_scale(&self) -> f64 {
        self.stiffness_scale
    }
}

/// The stiffness law's scale `c`, each tet's shares of its edges' constants, and the
/// stiffness per unit volume they give each tet, on the uncut mesh.
// PHYSICS.md §2.1 (k of eq. 1); the TetVolume law: docs/physics-notes.md, "Nakao".
fn initial_stiffness(
    params: &MassSpringParams,
    x: &[DVec3],
    tets: &[[u32; 4]],
) -> (f64, Vec<[f64; 6]>, Vec<TetTensor>) {
    let law = params.stiffness_law;
    let shapes: Vec<([(DVec3, f64); 6], f64)> = tets
        .iter()
        .map(|tet| {
            let p = tet.map(|i| x[i as usize]);
            (edge_frames(p), signed_volume(p))
        })
        .collect();
    // Σ_e W_e / d_e² = Σ_t Σ_{e ∈ t} V_t / d_e²: every tet-edge incidence.
    let incidences = shapes
        .iter()
        .flat_map(|(f, v)| f.iter().map(move |&(_, d)| (*v, d)));
    let edge_count = {
        let mut e: Vec<(u32, u32)> = tets
            .iter()
            .flat_map(|t| TET_EDGES.map(|(a, b)| (t[a].min(t[b]), t[a].max(t[b]))))
            .collect();
        e.sort_unstable();
        e.dedup();
        e.len()
    };
    let scale = match law {
        StiffnessLaw::Uniform => 1.0,
        StiffnessLaw::TetVolume => {
            let sum: f64 = incidences.map(|(v, d)| law.constant(1.0, 1.0, v, d)).sum();
            if sum > 0.0 {
                params.stiffness * edge_count as f64 / sum
            } else {
                1.0
            }
        }
    };
    let mut tet_k = Vec::with_capacity(tets.len());
    let mut material = Vec::with_capacity(tets.len());
    for (frames, v) in &shapes {
        let k = frames.map(|(_, d)| law.constant(params.stiffness, scale, *v, d));
        material.push(TetTensor::of_springs(frames, &k, *v));
        tet_k.push(k);
    }
    (scale, tet_k, material)
}

/// Signed volume of the tet with corners `p`.
pub(crate) fn signed_volume(p: [DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;
    use crate::mesh::EdgeList;

    #[test]
    fn model_of_a_block_has_its_edges_and_mass() {
        let (mesh, _) =
            TetMesh::from_raw(block(Vec3::ZERO, Vec3::splat(0.1), UVec3::new(2, 2, 1))).unwrap();
        let m = MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap();
        assert_eq!(m.edge_count(), EdgeList::of_mesh(&mesh).len());
        // The generator's coordinates are f32: 1e-6 relative is their rounding.
        let expected = 900.0 * 0.1 * 0.1 * 0.1;
        assert!((m.total_mass() - expected).abs() < 1e-6 * expected);
        assert!((m.initial_mass() - m.total_mass()).abs() < 1e-12 * expected);
        for i in 0..m.node_count() {
            for s in m.springs_of(i) {
                let back = m.springs_of(s.node as usize);
                assert!(
                    back.iter()
                        .any(|b| b.node as usize == i && b.rest == s.rest)
                );
            }
        }
    }

    #[test]
    fn fixing_an_unknown_node_is_an_error() {
        let (mesh, _) =
            TetMesh::from_raw(block(Vec3::ZERO, Vec3::ONE, UVec3::new(1, 1, 1))).unwrap();
        let mut m = MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap();
        assert!(matches!(
            m.fix(&[99], AxisMask::ALL),
            Err(MassSpringError::NodeOutOfRange { index: 99, .. })
        ));
    }
}
