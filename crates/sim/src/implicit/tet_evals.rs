//! The tets' evaluations at the Newton step's current iterate (forces, diagonal Hessian
//! blocks, energies and stress tangents), kept tet by tet (the scalar reference) or eight
//! tets to a chunk ([`super::eval_lanes`], what the SIMD product reads).

use glam::{Mat3, Vec3, Vec3A};

use super::eval_lanes::{self, EvalLanes};
use super::product_lanes::{RestLanes, TangentLanes, product_add, rest_lanes, tangent_lanes};
use super::product_parts::ProductParts;
use super::rest_tet::RestTet;
use super::tet_tangent::TetTangent;
use crate::material::Lame;
use crate::thread_team::{ThreadTeam, for_each_item, for_each_zip2};
use crate::vbd::{energy_density, piola};
use crate::xpbd::displacement_gradient;
use crate::xpbd::lanes::LANES;

/// One tet's evaluation at the current iterate.
#[derive(Debug, Clone, Copy)]
pub(super) struct TetEval {
    /// Nodal forces `V P b_a`.
    pub(super) forces: [Vec3; 4],
    /// Diagonal Hessian blocks.
    pub(super) diag: [Mat3; 4],
    /// Stress tangent.
    pub(super) tangent: TetTangent,
    /// `V Ψ`.
    pub(super) energy: f32,
}

/// Every tet's evaluation, in one of the two layouts.
pub(super) enum TetEvals {
    /// Tet by tet (`cpu_kernel: Scalar`, the reference).
    Scalar(Vec<TetEval>),
    /// In chunks of eight, with the chunks' rest data.
    Lanes {
        /// The chunks' nodes, `Dm⁻¹`, `V b_a` and volumes.
        rest: Vec<RestLanes>,
        /// Forces, blocks and energies.
        evals: Vec<EvalLanes>,
        /// Stress tangents.
        tangents: Vec<TangentLanes>,
    },
}

impl TetEvals {
    /// Every tet at rest (tangents of linear elasticity), in lanes or tet by tet.
    pub(super) fn at_rest(tets: &[RestTet], lame: Lame, lanes: bool) -> Self {
        let tangent = TetTangent::at_rest(lame);
        if !lanes {
            let rest = TetEval {
                forces: [Vec3::ZERO; 4],
                diag: [Mat3::ZERO; 4],
                tangent,
                energy: 0.0,
            };
            return TetEvals::Scalar(vec![rest; tets.len()]);
        }
        let rest = rest_lanes(tets);
        TetEvals::Lanes {
            evals: vec![EvalLanes::ZERO; rest.len()],
            tangents: vec![tangent_lanes(0, |_| tangent); rest.len()],
            rest,
        }
    }

    /// The force of tet `t` on its corner `a`.
    #[inline]
    pub(super) fn force(&self, t: usize, a: usize) -> Vec3 {
        match self {
            TetEvals::Scalar(e) => e[t].forces[a],
            TetEvals::Lanes { evals, .. } => evals[t / LANES].force(t % LANES, a),
        }
    }

    /// The diagonal Hessian block of tet `t` at its corner `a`.
    #[inline]
    pub(super) fn diag(&self, t: usize, a: usize) -> Mat3 {
        match self {
            TetEvals::Scalar(e) => e[t].diag[a],
            TetEvals::Lanes { evals, .. } => evals[t / LANES].diag(t % LANES, a),
        }
    }

    /// The stress tangent of tet `t`.
    pub(super) fn tangent(&self, t: usize) -> TetTangent {
        match self {
            TetEvals::Scalar(e) => e[t].tangent,
            TetEvals::Lanes { tangents, .. } => tangents[t / LANES].tangent(t % LANES),
        }
    }

    /// `Σ V Ψ` over the tets, in tet order, in f64.
    pub(super) fn elastic_energy(&self) -> f64 {
        match self {
            TetEvals::Scalar(e) => e.iter().map(|e| e.energy as f64).sum(),
            TetEvals::Lanes { evals, rest, .. } => evals
                .iter()
                .zip(rest)
                .flat_map(|(e, r)| e.energies()[..r.count].iter())
                .map(|&e| e as f64)
                .sum(),
        }
    }

    /// Evaluate every tet at `u` (`full` false: the energies alone, the rest kept) but
    /// those of the chunks of eight marked in `skip` (which keep their values).
    pub(super) fn evaluate(&mut self, tets: &[RestTet], at: Iterate, full: bool, skip: &[bool]) {
        let skipped = |c: usize| skip.get(c).copied().unwrap_or(false);
        match self {
            TetEvals::Scalar(evals) => {
                for_each(at.team, evals, |t, out| {
                    if !skipped(t / LANES) {
                        scalar_eval(&tets[t], &at.b[t], at, at.live[t], full, out)
                    }
                });
            }
            TetEvals::Lanes {
                rest,
                evals,
                tangents,
            } => {
                let run = |c: usize, out: &mut EvalLanes, tan: &mut TangentLanes| {
                    if skipped(c) {
                        return;
                    }
                    let live = &at.live[c * LANES..c * LANES + rest[c].count];
                    if full {
                        eval_lanes::evaluate(&rest[c], live, at.u, at.lame, out, tan);
                    } else {
                        eval_lanes::energy(&rest[c], live, at.u, at.lame, out);
                    }
                };
                for_each_zip2(at.team, (evals, tangents), MIN_PART / LANES, run);
            }
        }
    }
}

impl TetEvals {
    /// The live tets' nodal forces `V dP[dF(p)] b_a` for the direction `p = at.u` at the
    /// last evaluation's tangents, summed per node into `parts` (one node vector per fixed
    /// range of tets, [`ProductParts`]): the tets' part of the Hessian product. Only the
    /// chunks of eight tets listed in `active` are summed (those with a free node: the
    /// others' forces fall on fixed nodes alone), split into the parts in order, as
    /// [`ProductParts::set_chunks`] was given them.
    pub(super) fn products(
        &self,
        tets: &[RestTet],
        at: Iterate,
        active: &[u32],
        parts: &mut ProductParts,
    ) {
        let (parts, ranges) = parts.split();
        let run = |k: usize, sums: &mut Vec<Vec3A>| {
            sums[ranges[k].clone()].fill(Vec3A::ZERO);
            let mine = ProductParts::chunks(active, k);
            match self {
                TetEvals::Lanes { rest, tangents, .. } => {
                    for &c in mine {
                        let c = c as usize;
                        let live = &at.live[c * LANES..c * LANES + rest[c].count];
                        product_add(&rest[c], &tangents[c], live, at.u, sums);
                    }
                }
                TetEvals::Scalar(evals) => {
                    let tets_in = mine.iter().flat_map(|&c| {
                        c as usize * LANES..((c as usize + 1) * LANES).min(tets.len())
                    });
                    for t in tets_in.filter(|&t| at.live[t]) {
                        let f = scalar_product(&tets[t], &at.b[t], &evals[t].tangent, at.u);
                        for (&i, f) in tets[t].nodes.iter().zip(f) {
                            sums[i as usize] += Vec3A::from(f);
                        }
                    }
                }
            }
        };
        for_each_item(at.team, parts, 1, run);
    }
}

/// The chunks of eight tets (mesh order) with a live tet that has a free node: the
/// tets whose product forces reach a free node.
pub(super) fn active_chunks(tets: &[RestTet], live: &[bool], free: &[bool]) -> Vec<u32> {
    (0..tets.len().div_ceil(LANES))
        .filter(|&c| {
            (c * LANES..((c + 1) * LANES).min(tets.len()))
                .any(|t| live[t] && tets[t].nodes.iter().any(|&i| free[i as usize]))
        })
        .map(|c| c as u32)
        .collect()
}

/// One tet's nodal forces for the direction `p` (the reference for the lanes).
// docs/physics-notes.md, "The implicit scheme" (the exact Hessian, matrix-free).
fn scalar_product(tet: &RestTet, b: &[Vec3; 4], tangent: &TetTangent, p: &[Vec3]) -> [Vec3; 4] {
    let dp = tet.nodes.map(|i| p[i as usize]);
    let df = displacement_gradient(&dp, &tet.dm_inv);
    let stress = tangent.dp(&df) * tet.volume;
    b.map(|b| stress * b)
}

/// Where the tets are evaluated (or, for [`TetEvals::products`], the direction): the
/// displacements, which tets are live, the material, the shape gradients and the threads
/// the passes run on.
#[derive(Clone, Copy)]
pub(super) struct Iterate<'a> {
    /// Node displacements.
    pub(super) u: &'a [Vec3],
    /// Per tet, mesh order.
    pub(super) live: &'a [bool],
    /// The material.
    pub(super) lame: Lame,
    /// Shape gradients `b_a` per tet.
    pub(super) b: &'a [[Vec3; 4]],
    /// The threads the passes run on (`None`: this one).
    pub(super) team: Option<&'a ThreadTeam>,
}

/// One tet's evaluation (`full` false: its energy alone).
// PHYSICS.md §1.2 (the rest-free pair's energy); docs/physics-notes.md, "The implicit scheme".
fn scalar_eval(
    tet: &RestTet,
    b: &[Vec3; 4],
    at: Iterate,
    live: bool,
    full: bool,
    out: &mut TetEval,
) {
    if !live {
        out.energy = 0.0;
        out.forces = [Vec3::ZERO; 4];
        out.diag = [Mat3::ZERO; 4];
        return;
    }
    let s = tet.strain(at.u);
    out.energy = tet.volume * energy_density(&s, at.lame);
    if !full {
        return;
    }
    let p = piola(&s, at.lame) * tet.volume;
    out.tangent = TetTangent::at(&s, at.lame);
    for (a, ba) in b.iter().enumerate() {
        out.forces[a] = p * *ba;
        out.diag[a] = out.tangent.diagonal_block(tet.volume, *ba);
    }
}

/// Fewest items in a part of a pass on the team: nodes, or tets (in chunks of eight).
pub(super) const MIN_PART: usize = 256;

/// `f(i, &mut out[i])` for every item, on the team's threads where there is one.
pub(super) fn for_each<T: Send>(
    team: Option<&ThreadTeam>,
    out: &mut [T],
    f: impl Fn(usize, &mut T) + Sync,
) {
    for_each_item(team, out, MIN_PART, f);
}
