//! One blade advance, end to end (PHYSICS.md §2.3–2.4): the swept partial plane C,
//! crossed edges, (adaptive) node displacement, minimal subdivision, remodelling (node
//! duplication, spring removal, masses), (adaptive) rest-length update and smoothing.

use std::collections::{HashMap, HashSet};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::bisect::bisect_edges;
use super::crossing::{candidate_tets, find_crossings, tolerances};
use super::node_move::tets_quality;
use super::quad_centre::centre_quads;
use super::separate::separate;
use super::smooth::smooth;
use super::snap::{Moved, Snapper};
use super::split_order::{SplitQuality, plan_split};
use super::{BladePose, SweptRegion};
use crate::mass_spring::MassSpringModel;

/// How crossed tets are subdivided.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Subdivision {
    /// Nakao 2003: node displacement onto the cut boundary (and onto the plane near nodes),
    /// split order by dihedral angles, rest-length update and Laplacian smoothing.
    #[default]
    Adaptive,
    /// The baseline (Bielser & Gross 2000 style): split at the crossings as they are, in a
    /// fixed order, nothing moved; a partially crossed tet is split only on the edges C has
    /// crossed so far.
    NonAdaptive,
    /// The baseline after Bielser & Gross 2000 as Nakao 2003 counts it (3–5 new vertices,
    /// 4–9 tets per cut tet): the non-adaptive split plus a centre vertex on every
    /// quadrilateral cut face (`quad_centre.rs`; reconstructed from the counts).
    Bielser,
}

/// Settings of the cutter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CutParams {
    /// Adaptive or non-adaptive subdivision.
    pub subdivision: Subdivision,
    /// Adaptive: a crossing this close to a node (fraction of the edge) moves the node onto
    /// the plane instead.
    pub snap_fraction: f64,
    /// Adaptive: farthest a node may move onto the cut boundary, in local edge lengths.
    pub max_boundary_move: f64,
    /// Adaptive: Laplacian smoothing passes over the nodes around the cut.
    pub smoothing_iterations: u32,
    /// Adaptive: fraction of the way to the neighbours' mean a smoothing pass moves a node.
    pub smoothing_weight: f64,
    /// Crossing parameters are clamped to `[f, 1 − f]` so no split makes a flat tet.
    pub min_fraction: f64,
}

impl Default for CutParams {
    fn default() -> Self {
        CutParams {
            subdivision: Subdivision::Adaptive,
            snap_fraction: 0.15,
            max_boundary_move: 0.15,
            smoothing_iterations: 2,
            smoothing_weight: 0.5,
            min_fraction: 0.02,
        }
    }
}

impl CutParams {
    /// Ok, or the first field out of range and why.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let frac = |v: f64, hi: f64| v.is_finite() && (0.0..=hi).contains(&v);
        if !frac(self.snap_fraction, 0.5) {
            return Err((
                "snap_fraction",
                format!("must lie in [0, 0.5], got {}", self.snap_fraction),
            ));
        }
        if !frac(self.max_boundary_move, 2.0) {
            return Err((
                "max_boundary_move",
                format!(
                    "must lie in [0, 2] edge lengths, got {}",
                    self.max_boundary_move
                ),
            ));
        }
        if !frac(self.smoothing_weight, 1.0) {
            return Err((
                "smoothing_weight",
                format!("must lie in [0, 1], got {}", self.smoothing_weight),
            ));
        }
        if !(self.min_fraction.is_finite() && self.min_fraction > 0.0 && self.min_fraction < 0.25) {
            return Err((
                "min_fraction",
                format!("must lie in (0, 0.25), got {}", self.min_fraction),
            ));
        }
        Ok(())
    }
}

/// What one blade advance did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CutReport {
    /// Edges split at their crossing with C.
    pub split_edges: usize,
    /// Nodes created (split points and duplicates).
    pub new_nodes: usize,
    /// Tets added by subdivision.
    pub new_tets: usize,
    /// Nodes duplicated to open the cut.
    pub duplicated_nodes: usize,
    /// Interior faces opened.
    pub opened_faces: usize,
    /// Nodes moved onto the cut boundary or plane (adaptive).
    pub moved_nodes: usize,
    /// Nodes moved by smoothing (adaptive).
    pub smoothed_nodes: usize,
    /// Smallest dihedral angle of the tets the advance created or reshaped, degrees
    /// (+∞ when it created none).
    pub worst_dihedral_deg: f64,
    /// Wall time of the advance, ms.
    pub ms: f64,
    /// Whether the advance changed the model beyond its positions, velocities and time
    /// (nodes, tets, cut faces, springs, masses or reference positions, also by moves it
    /// undid): a caller that keeps a copy of the model for a rollback must renew it.
    pub remodelled: bool,
}

/// The cutting tool: follows the blade from pose to pose and cuts the model.
#[derive(Debug, Clone)]
pub struct Cutter {
    params: CutParams,
    pose: Option<BladePose>,
    /// Nodes on the current stroke's cut surface.
    on_cut: HashSet<u32>,
    /// Regions swept so far in the current stroke.
    stroke: Vec<SweptRegion>,
    /// Crossing nodes of the current stroke by the edge each split ([`Subdivision::Bielser`]).
    crossing_parents: HashMap<u32, [u32; 2]>,
    margin: f64,
}

impl Cutter {
    /// A cutter with `params` (see [`CutParams::validate`]).
    pub fn new(params: CutParams) -> Self {
        Cutter {
            params,
            pose: None,
            on_cut: HashSet::new(),
            stroke: Vec::new(),
            crossing_parents: HashMap::new(),
            margin: 0.0,
        }
    }

    /// The settings in use.
    pub fn params(&self) -> &CutParams {
        &self.params
    }

    /// Replace the settings; the stroke in progress continues with them.
    pub fn set_params(&mut self, params: CutParams) {
        self.params = params;
    }

    /// Start a stroke with the blade at `pose` (nothing is cut yet).
    pub fn begin(&mut self, model: &MassSpringModel, pose: BladePose) {
        self.pose = Some(pose);
        self.on_cut.clear();
        self.stroke.clear();
        self.crossing_parents.clear();
        // A tet meeting C has a node within its longest edge of C.
        let x = model.positions();
        self.margin = 1.5
            * (0..model.node_count())
                .flat_map(|i| {
                    model
                        .springs_of(i)
                        .iter()
                        .map(move |s| (x[s.node as usize] - x[i]).length())
                })
                .fold(0.0, f64::max);
    }

    /// Lift the blade: the next [`Cutter::advance`] starts a new stroke.
    pub fn end(&mut self) {
        self.pose = None;
        self.on_cut.clear();
        self.stroke.clear();
        self.crossing_parents.clear();
    }

    /// Move the blade to `pose`, cutting what it sweeps from the previous pose. The first
    /// call after [`Cutter::end`] (or without [`Cutter::begin`]) only places the blade.
    pub fn advance(&mut self, model: &mut MassSpringModel, pose: BladePose) -> CutReport {
        let start = Instant::now();
        let Some(from) = self.pose.replace(pose) else {
            self.begin(model, pose);
            return CutReport {
                worst_dihedral_deg: f64::INFINITY,
                ..CutReport::default()
            };
        };
        let mut report = match SweptRegion::new(from, pose) {
            Some(region) => {
                let report = self.cut(model, &region);
                self.stroke.push(region);
                report
            }
            None => CutReport {
                worst_dihedral_deg: f64::INFINITY,
                ..CutReport::default()
            },
        };
        report.ms = start.elapsed().as_secs_f64() * 1e3;
        report
    }

    fn cut(&mut self, model: &mut MassSpringModel, region: &SweptRegion) -> CutReport {
        let p = self.params.clone();
        let nodes_before = model.node_count();
        let tets_before = model.tet_count();
        let candidates = candidate_tets(model, region, self.margin);
        let tol = tolerances(model, &candidates);
        let on_cut = &mut self.on_cut;
        let earlier = &self.stroke;
        let find = |model: &MassSpringModel, on_cut: &HashSet<u32>| {
            find_crossings(
                model,
                region,
                earlier,
                &candidates,
                &tol,
                p.min_fraction,
                on_cut,
            )
        };
        let mut cross = find(model, on_cut);
        // The non-adaptive split of this advance: its worst angle is the floor that the
        // adaptive moves must respect.
        let baseline = plan_split(model, &cross.split, false);
        let mut moved: Vec<Moved> = Vec::new();
        // Moves undone below still leave their rounding in the reference positions.
        let mut undone = false;
        let plan = if p.subdivision == Subdivision::Adaptive && !cross.split.is_empty() {
            let floor = baseline.quality.min_deg;
            let snapper = Snapper {
                region,
                tol: &tol,
                floor_deg: floor,
            };
            snapper.near_nodes(model, &cross, p.snap_fraction, &mut moved);
            on_cut.extend(moved.iter().map(|m| m.node));
            cross = find(model, on_cut);
            for _ in 0..8 {
                let max_move = p.max_boundary_move * tol.edge;
                if cross.straddling.is_empty()
                    || !snapper.to_boundary(model, &cross, max_move, on_cut, &mut moved)
                {
                    break;
                }
                on_cut.extend(moved.iter().map(|m| m.node));
                cross = find(model, on_cut);
            }
            let plan = plan_split(model, &cross.split, true);
            let reshaped = moved_star_quality(model, &moved);
            if plan.quality.merge(reshaped).min_deg < floor - 1e-9 {
                // The moves did not pay off: undo them and split as the baseline would,
                // in the best order.
                undone = !moved.is_empty();
                for m in moved.drain(..).rev() {
                    model.displace(m.node as usize, -m.by);
                    on_cut.remove(&m.node);
                }
                cross = find(model, on_cut);
                plan_split(model, &cross.split, true)
            } else {
                plan
            }
        } else {
            baseline
        };
        // Old nodes lying on the plane inside C are on the cut surface too.
        for (&v, &d) in &cross.distance {
            if d.abs() <= tol.on_plane
                && region.contains(region.project(model.positions()[v as usize]), tol.in_region)
            {
                on_cut.insert(v);
            }
        }
        let mut bisection = bisect_edges(model, &cross.split, &plan.order);
        if p.subdivision == Subdivision::Bielser {
            let centres = centre_quads(model, &bisection, &mut self.crossing_parents);
            bisection.absorb(centres);
        }
        on_cut.extend(&bisection.new_nodes);
        // Only the cut nodes near this advance can bound a face to open now.
        let mut local: Vec<u32> = cross
            .distance
            .keys()
            .chain(&bisection.new_nodes)
            .filter(|v| on_cut.contains(v))
            .flat_map(|&v| model.tets_of(v as usize).to_vec())
            .collect();
        local.sort_unstable();
        local.dedup();
        let separation = separate(model, &local, |v| on_cut.contains(&v));
        on_cut.extend(separation.duplicated.iter().map(|d| d[1]));
        let mut affected: Vec<u32> = bisection
            .touched_tets
            .iter()
            .chain(&separation.touched_tets)
            .flat_map(|&t| model.tets()[t as usize])
            .chain(moved.iter().map(|m| m.node))
            .chain(separation.duplicated.iter().flatten().copied())
            .collect();
        affected.sort_unstable();
        affected.dedup();
        // Tets the advance created or reshaped: smoothing may not make their worst worse.
        let mut created: HashSet<u32> = bisection.touched_tets.iter().copied().collect();
        created.extend(
            moved
                .iter()
                .flat_map(|m| model.tets_of(m.node as usize).to_vec()),
        );
        let mut smoothed = Vec::new();
        if p.subdivision == Subdivision::Adaptive && p.smoothing_iterations > 0 {
            let ring: Vec<u32> = affected
                .iter()
                .copied()
                .filter(|v| !on_cut.contains(v))
                .collect();
            smoothed = smooth(
                model,
                &ring,
                &created,
                p.smoothing_weight,
                p.smoothing_iterations,
            );
            affected.extend(&smoothed);
            affected.extend(
                smoothed
                    .iter()
                    .flat_map(|&v| model.tets_of(v as usize).to_vec())
                    .flat_map(|t| model.tets()[t as usize]),
            );
            affected.sort_unstable();
            affected.dedup();
        }
        model.recompute_masses(&affected);
        model.rebuild_springs(&affected);
        model.refresh_stability_near(&affected);
        model.twins.extend_from_slice(&separation.duplicated);
        let mut judged: Vec<u32> = bisection.touched_tets.clone();
        judged.extend(
            moved
                .iter()
                .flat_map(|m| model.tets_of(m.node as usize).to_vec()),
        );
        judged.sort_unstable();
        judged.dedup();

        CutReport {
            split_edges: cross.split.len(),
            new_nodes: model.node_count() - nodes_before,
            new_tets: model.tet_count() - tets_before,
            duplicated_nodes: separation.duplicated.len(),
            opened_faces: separation.opened_faces,
            moved_nodes: moved.len(),
            smoothed_nodes: smoothed.len(),
            worst_dihedral_deg: tets_quality(model, &judged).min_deg,
            ms: 0.0,
            remodelled: undone
                || !affected.is_empty()
                || separation.flagged_faces > 0
                || model.node_count() != nodes_before
                || model.tet_count() != tets_before,
        }
    }
}

/// Quality of the tets around the moved nodes.
fn moved_star_quality(model: &MassSpringModel, moved: &[Moved]) -> SplitQuality {
    let tets: Vec<u32> = moved
        .iter()
        .flat_map(|m| model.tets_of(m.node as usize).to_vec())
        .collect();
    tets_quality(model, &tets)
}
