//! The objective metrics of an attempt, computed from the simulation state at the end
//! (which tets were released, in rest coordinates) and the per-frame tool statistics.
//! Definitions and formulas: docs/scoring.md.

use glam::DVec3;
use incise_sim::TetMesh;
use incise_sim::xpbd::FrameStats;
use serde::Serialize;

use super::model::Exercise;
use super::plan::Plan;

/// Frames without contact that still belong to the same blade engagement: shorter gaps
/// (below 0.1 s at 60 Hz) are contact flicker, not a new stroke.
pub const STROKE_GAP_FRAMES: usize = 6;

/// A released boundary face counts as part of the surface trace when its outward normal
/// is within 60° of the plan's surface normal (cos 60° = 0.5).
const TRACE_NORMAL_COS: f64 = 0.5;

/// The metrics of one attempt (SI units; docs/scoring.md).
#[derive(Debug, Clone, Serialize)]
pub struct Metrics {
    /// Length of the plan on the surface, m.
    pub plan_length: f64,
    /// Mean edge length of the tet mesh, m (the resolution of every length below).
    pub tet_edge: f64,
    /// Released tets in all.
    pub released_tets: usize,
    /// Released boundary faces on the plan's side of the organ (the surface trace).
    pub trace_faces: usize,
    /// Mean distance of the trace from the plan, m; absent when nothing was cut.
    pub mean_deviation: Option<f64>,
    /// Largest distance of the trace from the plan, m; absent when nothing was cut.
    pub max_deviation: Option<f64>,
    /// Fraction of the plan's length with a trace within the lateral tolerance (0..1).
    pub completion: f64,
    /// Mean |cut depth − target| over the cut part of the plan, m; absent when nothing
    /// was cut.
    pub mean_depth_error: Option<f64>,
    /// Deepest cut within the lateral band, m (0 when nothing was cut).
    pub max_depth: f64,
    /// Rest volume of released tets outside the tolerance band, m³.
    pub collateral_volume: f64,
    /// Rest volume of all released tets, m³.
    pub released_volume: f64,
    /// Volume of the tolerance band (plan length × 2 lateral tolerance × (target depth +
    /// depth tolerance)), m³: the scale of collateral damage in the score.
    pub band_volume: f64,
    /// Largest contact force on the blade, N.
    pub max_force: f64,
    /// Mean contact force over the frames with contact, N (0 without contact).
    pub mean_force: f64,
    /// Blade engagements: runs of frames with contact, gaps under
    /// [`STROKE_GAP_FRAMES`] bridged.
    pub strokes: usize,
    /// Time from the first to the last frame with contact, s.
    pub duration: f64,
    /// Cut depth along the plan: (arc length, depth), m; 0 where uncut.
    pub depth_profile: Vec<(f64, f64)>,
    /// Contact force over time: (time, |force|), s and N.
    pub force_series: Vec<(f64, f64)>,
}

/// Compute the metrics of an attempt: `released[t]` says whether tet `t` was released,
/// `frames` are the run's frames (each `dt` long).
pub fn compute(
    exercise: &Exercise,
    plan: &Plan,
    mesh: &TetMesh,
    released: &[bool],
    frames: &[FrameStats],
    dt: f64,
) -> Metrics {
    let x = |i: u32| mesh.rest_positions[i as usize].as_dvec3();
    let lateral_tol = exercise.tolerance.lateral as f64;
    let target = exercise.depth as f64;
    let max_allowed_depth = target + exercise.tolerance.depth as f64;
    let tet_edge = mesh.mean_edge_length() as f64;
    // Samples within this arc length of a cut count as cut (a tet spans about one edge).
    let window = 0.5 * tet_edge;
    let n = plan.samples.len();

    // The surface trace: released tets' boundary faces facing the plan's side.
    let mut trace: Vec<(usize, f64)> = Vec::new();
    for &(t, f) in &mesh.boundary {
        if !released[t as usize] {
            continue;
        }
        let [a, b, c] = mesh.face_nodes(t as usize, f as usize).map(x);
        let centre = (a + b + c) / 3.0;
        let tet = mesh.tets[t as usize];
        let tet_centre = tet.iter().map(|&i| x(i)).sum::<DVec3>() / 4.0;
        let mut normal = (b - a).cross(c - a).normalize_or_zero();
        if normal.dot(a - tet_centre) < 0.0 {
            normal = -normal;
        }
        let at = plan.locate(centre);
        if normal.dot(plan.samples[at.sample].normal) >= TRACE_NORMAL_COS {
            trace.push((at.sample, at.lateral));
        }
    }
    let mut covered = vec![false; n];
    for &(sample, lateral) in &trace {
        if lateral <= lateral_tol {
            mark_window(&mut covered, plan, sample, window);
        }
    }

    // Depth along the plan and collateral volume, from every released tet.
    let mut depth = vec![0.0f64; n];
    let mut collateral_volume = 0.0;
    let mut released_volume = 0.0;
    let mut released_tets = 0;
    for (t, tet) in mesh.tets.iter().enumerate() {
        if !released[t] {
            continue;
        }
        released_tets += 1;
        let volume = mesh.rest_volume[t] as f64;
        released_volume += volume;
        let centre = tet.iter().map(|&i| x(i)).sum::<DVec3>() / 4.0;
        let at = plan.locate(centre);
        let smp = plan.samples[at.sample];
        if at.lateral > lateral_tol || at.depth > max_allowed_depth {
            collateral_volume += volume;
        }
        if at.lateral <= lateral_tol {
            let deepest = tet
                .iter()
                .map(|&i| (smp.point - x(i)).dot(smp.normal))
                .fold(0.0, f64::max);
            for_window(plan, at.sample, window, |j| {
                depth[j] = depth[j].max(deepest)
            });
        }
    }
    let cut: Vec<usize> = (0..n).filter(|&j| covered[j]).collect();
    let completion = cut.len() as f64 / n.max(1) as f64;
    let mean_depth_error = (!cut.is_empty())
        .then(|| cut.iter().map(|&j| (depth[j] - target).abs()).sum::<f64>() / cut.len() as f64);
    let max_depth = depth.iter().copied().fold(0.0, f64::max);
    let (mean_deviation, max_deviation) = match trace.len() {
        0 => (None, None),
        k => (
            Some(trace.iter().map(|t| t.1).sum::<f64>() / k as f64),
            Some(trace.iter().map(|t| t.1).fold(0.0, f64::max)),
        ),
    };

    // Tool figures.
    let force: Vec<f64> = frames
        .iter()
        .map(|f| f.tool_force.length() as f64)
        .collect();
    let contact: Vec<usize> = (0..frames.len())
        .filter(|&i| frames[i].contact_nodes > 0)
        .collect();
    let max_force = force.iter().copied().fold(0.0, f64::max);
    let mean_force = match contact.len() {
        0 => 0.0,
        k => contact.iter().map(|&i| force[i]).sum::<f64>() / k as f64,
    };
    let strokes = match contact.first() {
        None => 0,
        Some(_) => {
            1 + contact
                .windows(2)
                .filter(|w| w[1] - w[0] > STROKE_GAP_FRAMES)
                .count()
        }
    };
    let duration = match (contact.first(), contact.last()) {
        (Some(a), Some(b)) => (b - a + 1) as f64 * dt,
        _ => 0.0,
    };
    Metrics {
        plan_length: plan.length,
        tet_edge,
        released_tets,
        trace_faces: trace.len(),
        mean_deviation,
        max_deviation,
        completion,
        mean_depth_error,
        max_depth,
        collateral_volume,
        released_volume,
        band_volume: plan.length * 2.0 * lateral_tol * max_allowed_depth,
        max_force,
        mean_force,
        strokes,
        duration,
        depth_profile: plan.samples.iter().map(|s| s.s).zip(depth).collect(),
        force_series: frames
            .iter()
            .zip(&force)
            .map(|(f, &g)| (f.sim_time, g))
            .collect(),
    }
}

/// Call `f` for every sample within `window` arc length of sample `centre`.
fn for_window(plan: &Plan, centre: usize, window: f64, mut f: impl FnMut(usize)) {
    let s = plan.samples[centre].s;
    let lo = plan.samples[..centre]
        .iter()
        .rposition(|p| s - p.s > window)
        .map_or(0, |i| i + 1);
    let hi = plan.samples[centre..]
        .iter()
        .position(|p| p.s - s > window)
        .map_or(plan.samples.len(), |i| centre + i);
    (lo..hi).for_each(&mut f);
}

fn mark_window(covered: &mut [bool], plan: &Plan, centre: usize, window: f64) {
    for_window(plan, centre, window, |j| covered[j] = true);
}
