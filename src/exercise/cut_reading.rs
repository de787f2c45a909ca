//! Reading an attempt's cut against the plan (docs/scoring.md, "Metrics"): its surface
//! trace, its depth along the plan and the tissue it damaged outside the band, from the
//! tets an XPBD body released or from the cut surface a Nakao body opened, both at rest.

use std::collections::HashSet;

use glam::DVec3;
use incise_sim::TetMesh;

use super::band::Band;
use super::plan::{Plan, for_window};
use crate::sim_body::RestCutFace;

/// A released boundary face counts as part of the surface trace when its outward normal
/// is within 60° of the plan's surface normal (cos 60° = 0.5).
const TRACE_NORMAL_COS: f64 = 0.5;

/// A cut face belongs to the cut's mouth (its surface trace) when a corner lies within
/// this fraction of the mean tet edge of the surface.
const MOUTH_DEPTH: f64 = 0.25;

/// What a cut's reading found.
pub struct CutFound {
    /// The surface trace: (nearest plan sample, lateral distance) per face.
    pub trace: Vec<(usize, f64)>,
    /// Cut depth at each plan sample, m (0 where uncut).
    pub depth: Vec<f64>,
    /// Released tets.
    pub released_tets: usize,
    /// Their rest volume, m³.
    pub released_volume: f64,
    /// Rest volume damaged outside the band, m³.
    pub collateral_volume: f64,
    /// Faces of the cut surface.
    pub cut_faces: usize,
    /// Rest area of the cut surface, m².
    pub cut_area: f64,
}

/// The reading of released tets (`released[t]`): the trace is their boundary faces
/// facing the plan's side, the depth their deepest nodes, the collateral their volume
/// outside the band.
pub fn released_cut(plan: &Plan, mesh: &TetMesh, released: &[bool], band: &Band) -> CutFound {
    let x = |i: u32| mesh.rest_positions[i as usize].as_dvec3();
    let mut trace: Vec<(usize, f64)> = Vec::new();
    for &(t, f) in &mesh.boundary {
        if !released[t as usize] {
            continue;
        }
        let [a, b, c] = mesh.face_nodes(t as usize, f as usize).map(x);
        let centre = (a + b + c) / 3.0;
        let tet_centre = mesh.tets[t as usize].iter().map(|&i| x(i)).sum::<DVec3>() / 4.0;
        let mut normal = (b - a).cross(c - a).normalize_or_zero();
        if normal.dot(a - tet_centre) < 0.0 {
            normal = -normal;
        }
        let at = plan.locate(centre);
        if normal.dot(plan.samples[at.sample].normal) >= TRACE_NORMAL_COS {
            trace.push((at.sample, at.lateral));
        }
    }
    let mut found = CutFound::empty(trace, plan.samples.len());
    for (t, tet) in mesh.tets.iter().enumerate() {
        if !released[t] {
            continue;
        }
        let volume = mesh.rest_volume[t] as f64;
        found.released_tets += 1;
        found.released_volume += volume;
        let corners = tet.map(x);
        let at = plan.locate(corners.iter().sum::<DVec3>() / 4.0);
        if at.lateral > band.lateral || at.depth > band.max_depth {
            found.collateral_volume += volume;
        }
        if at.lateral <= band.lateral {
            found.deepen(plan, at.sample, &corners, band);
        }
    }
    found
}

/// The reading of a cut surface (both sides of the wound, at rest): the trace is its
/// faces at the mouth (a corner within [`MOUTH_DEPTH`] `h` of the surface), the depth
/// their deepest corners, the collateral the volume of the tets it bounds outside the
/// band (each tet once).
pub fn surface_cut(plan: &Plan, faces: &[RestCutFace], band: &Band) -> CutFound {
    let mut found = CutFound::empty(Vec::new(), plan.samples.len());
    let mut damaged: HashSet<u32> = HashSet::new();
    for face in faces {
        let at = plan.locate(face.centroid());
        let [a, b, c] = face.corners;
        found.cut_faces += 1;
        found.cut_area += 0.5 * (b - a).cross(c - a).length();
        let smp = plan.samples[at.sample];
        let mouth = face
            .corners
            .iter()
            .any(|&p| (smp.point - p).dot(smp.normal) <= MOUTH_DEPTH * band.tet_edge);
        if mouth {
            found.trace.push((at.sample, at.lateral));
        }
        let outside = at.lateral > band.lateral || at.depth > band.max_depth;
        if outside && damaged.insert(face.tet) {
            found.collateral_volume += face.tet_volume;
        }
        if at.lateral <= band.lateral {
            found.deepen(plan, at.sample, &face.corners, band);
        }
    }
    found
}

impl CutFound {
    fn empty(trace: Vec<(usize, f64)>, samples: usize) -> CutFound {
        CutFound {
            trace,
            depth: vec![0.0; samples],
            released_tets: 0,
            released_volume: 0.0,
            collateral_volume: 0.0,
            cut_faces: 0,
            cut_area: 0.0,
        }
    }

    /// Deepen the cut within the window around `sample` to the deepest of `points` below
    /// that sample's surface.
    fn deepen(&mut self, plan: &Plan, sample: usize, points: &[DVec3], band: &Band) {
        let smp = plan.samples[sample];
        let deepest = points
            .iter()
            .map(|&p| (smp.point - p).dot(smp.normal))
            .fold(0.0, f64::max);
        let depth = &mut self.depth;
        for_window(plan, sample, band.window, |j| {
            depth[j] = depth[j].max(deepest)
        });
    }
}
