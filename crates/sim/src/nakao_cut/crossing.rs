//! Which nodes lie on which side of the blade's plane, and which edges the partial plane
//! C crosses (PHYSICS.md §2.4: a plane meets a tet in a quad or a triangle).

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::SweptRegion;
use crate::mass_spring::MassSpringModel;
use crate::mesh::TET_EDGES;

/// An edge that C crosses, to be split at `lerp(a, b, t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SplitEdge {
    /// Lower node index.
    pub a: u32,
    /// Higher node index.
    pub b: u32,
    /// Crossing parameter from `a` (clamped to `[f, 1 − f]`).
    pub t: f64,
}

/// Tolerances of one blade advance, from the local edge length `h`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tolerances {
    /// Nodes closer than this to the plane count as on it, m.
    pub on_plane: f64,
    /// Points this close to C's boundary count as inside, m.
    pub in_region: f64,
    /// Mean reference edge length around the cut, m.
    pub edge: f64,
}

/// The crossing state of the tets near one blade advance.
#[derive(Debug, Clone, Default)]
pub(crate) struct Crossings {
    /// Signed distance from the plane of every node of the candidate tets.
    pub distance: HashMap<u32, f64>,
    /// Edges crossing the plane inside C, sorted by (a, b).
    pub split: Vec<SplitEdge>,
    /// Tets crossed partially: some crossing edges inside C, some outside.
    pub straddling: Vec<u32>,
}

/// Tets near the swept region that touch or cross its plane: those with a node within
/// `margin` of its bounding box and nodes on both sides of (or on) the plane. Moving a node
/// onto the plane cannot make a tet outside this set cross it.
pub(crate) fn candidate_tets(
    model: &MassSpringModel,
    region: &SweptRegion,
    margin: f64,
) -> Vec<u32> {
    let (lo, hi) = region.bounds();
    let (lo, hi) = (lo - DVec3::splat(margin), hi + DVec3::splat(margin));
    let mut tets: Vec<u32> = model
        .positions()
        .iter()
        .enumerate()
        .filter(|(_, p)| p.cmpge(lo).all() && p.cmple(hi).all())
        .flat_map(|(i, _)| model.tets_of(i).iter().copied())
        .collect();
    tets.sort_unstable();
    tets.dedup();
    let x = model.positions();
    let slack = 1e-9 * margin;
    tets.retain(|&t| {
        let d = model.tets()[t as usize].map(|v| region.signed_distance(x[v as usize]));
        let (lo, hi) = d
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        lo <= slack && hi >= -slack
    });
    tets
}

/// Tolerances for `tets`: on-plane 1e-9 h, in-region 1e-7 h, h their mean reference edge.
pub(crate) fn tolerances(model: &MassSpringModel, tets: &[u32]) -> Tolerances {
    let x = model.reference_positions();
    let (mut sum, mut count) = (0.0, 0usize);
    for &t in tets {
        let tet = model.tets()[t as usize];
        for (a, b) in TET_EDGES {
            sum += (x[tet[a] as usize] - x[tet[b] as usize]).length();
            count += 1;
        }
    }
    let edge = if count > 0 { sum / count as f64 } else { 1.0 };
    Tolerances {
        on_plane: 1e-9 * edge,
        in_region: 1e-7 * edge,
        edge,
    }
}

/// Classify the nodes of `tets` against the plane of `region` (the current advance) and
/// collect the edges the stroke crosses: their crossing point lies in `region` or in an
/// earlier advance's region of the same stroke (`earlier`, within `0.05 h` of its plane), so
/// that an edge the tissue carried across the cut after the blade passed is still split.
///
/// Nodes in `on_cut` (already on this stroke's cut surface) count as on the plane even
/// when the tissue has moved them slightly off it since.
/// An edge crosses when its ends lie strictly on opposite sides (farther than the on-plane
/// tolerance); it is split when its crossing point lies in C. The crossing parameter is
/// clamped to `[min_fraction, 1 − min_fraction]` so that no split creates a flat tet.
pub(crate) fn find_crossings(
    model: &MassSpringModel,
    region: &SweptRegion,
    earlier: &[SweptRegion],
    tets: &[u32],
    tol: &Tolerances,
    min_fraction: f64,
    on_cut: &HashSet<u32>,
) -> Crossings {
    let x = model.positions();
    let mut distance = HashMap::with_capacity(tets.len());
    for &t in tets {
        for v in model.tets()[t as usize] {
            distance
                .entry(v)
                .or_insert_with(|| region.signed_distance(x[v as usize]));
        }
    }
    let side = |v: u32| {
        let d = distance[&v];
        if on_cut.contains(&v) {
            0
        } else if d > tol.on_plane {
            1
        } else if d < -tol.on_plane {
            -1
        } else {
            0
        }
    };
    let mut split: HashMap<(u32, u32), Option<f64>> = HashMap::new();
    let mut straddling = Vec::new();
    for &t in tets {
        let tet = model.tets()[t as usize];
        let (mut inside, mut outside) = (0, 0);
        for (i, j) in TET_EDGES {
            let (a, b) = (tet[i].min(tet[j]), tet[i].max(tet[j]));
            if side(a) * side(b) >= 0 {
                continue;
            }
            let entry = *split.entry((a, b)).or_insert_with(|| {
                let (da, db) = (distance[&a], distance[&b]);
                let t = da / (da - db);
                let q = x[a as usize].lerp(x[b as usize], t);
                let swept = region.contains(region.project(q), tol.in_region)
                    || earlier
                        .iter()
                        .any(|r| r.contains_point(q, 0.05 * tol.edge, tol.in_region));
                swept.then(|| t.clamp(min_fraction, 1.0 - min_fraction))
            });
            if entry.is_some() {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        if inside > 0 && outside > 0 {
            straddling.push(t);
        }
    }
    let mut split: Vec<SplitEdge> = split
        .into_iter()
        .filter_map(|((a, b), t)| t.map(|t| SplitEdge { a, b, t }))
        .collect();
    split.sort_by_key(|e| (e.a, e.b));
    Crossings {
        distance,
        split,
        straddling,
    }
}
