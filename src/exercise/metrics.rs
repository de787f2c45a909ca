//! The objective metrics of an attempt, computed from what the body cut at the end (the
//! tets it released or the cut surface it opened, in rest coordinates) and the per-frame
//! tool statistics. Definitions and formulas: docs/scoring.md.

use glam::DVec3;
use incise_sim::TetMesh;
use incise_sim::xpbd::FrameStats;
use serde::Serialize;

use super::band::Band;
use super::cut_reading::{released_cut, surface_cut};
use super::model::Exercise;
use super::plan::{Plan, for_window};
use crate::report::FrameData;
use crate::sim_body::RestCut;

/// Frames without contact that still belong to the same blade engagement: shorter gaps
/// (below 0.1 s at 60 Hz) are contact flicker, not a new stroke.
pub const STROKE_GAP_FRAMES: usize = 6;

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
    /// Rest volume of released tets outside the tolerance band (a cut surface: of the
    /// tets it bounds there), m³.
    pub collateral_volume: f64,
    /// Rest volume of all released tets, m³.
    pub released_volume: f64,
    /// Faces of the cut surface (a method that cuts by remodelling; 0 for XPBD).
    pub cut_faces: usize,
    /// Rest area of the cut surface, both sides, m² (0 for XPBD).
    pub cut_area: f64,
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

/// One frame's tool figures, whatever the method.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ToolFrame {
    /// Simulated time at the end of the frame, s.
    pub time: f64,
    /// |force| of the tissue on the blade, N.
    pub force: f64,
    /// Whether the blade touched the tissue.
    pub contact: bool,
}

impl ToolFrame {
    /// An XPBD frame's: contact when some node touched the blade's spheres.
    pub fn of_xpbd(s: &FrameStats) -> ToolFrame {
        ToolFrame {
            time: s.sim_time,
            force: s.tool_force.length() as f64,
            contact: s.contact_nodes > 0,
        }
    }

    /// Any method's frame (a frame without a blade has no force and no contact).
    pub fn of(frame: &FrameData) -> ToolFrame {
        match frame {
            FrameData::Xpbd(s) => ToolFrame::of_xpbd(s),
            FrameData::Edges(s) => ToolFrame {
                time: s.sim_time,
                force: s.tool_force.map_or(0.0, |f| DVec3::from_array(f).length()),
                contact: s.blade_contact.unwrap_or(false),
            },
        }
    }
}

/// Compute the metrics of an attempt from what the body cut at rest (`cut`: its
/// released tets, or its cut surface) and the run's `frames` (each `dt` long).
pub fn compute(
    exercise: &Exercise,
    plan: &Plan,
    mesh: &TetMesh,
    cut: &RestCut,
    frames: &[ToolFrame],
    dt: f64,
) -> Metrics {
    let band = Band::of(exercise, mesh);
    let found = match cut {
        RestCut::Released(released) => released_cut(plan, mesh, released, &band),
        RestCut::Faces(faces) => surface_cut(plan, faces, &band),
    };
    let n = plan.samples.len();
    let mut covered = vec![false; n];
    for &(sample, lateral) in &found.trace {
        if lateral <= band.lateral {
            for_window(plan, sample, band.window, |j| covered[j] = true);
        }
    }
    let cut_samples: Vec<usize> = (0..n).filter(|&j| covered[j]).collect();
    let completion = cut_samples.len() as f64 / n.max(1) as f64;
    let depth = &found.depth;
    let mean_depth_error = (!cut_samples.is_empty()).then(|| {
        cut_samples
            .iter()
            .map(|&j| (depth[j] - band.target).abs())
            .sum::<f64>()
            / cut_samples.len() as f64
    });
    let trace = &found.trace;
    let (mean_deviation, max_deviation) = match trace.len() {
        0 => (None, None),
        k => (
            Some(trace.iter().map(|t| t.1).sum::<f64>() / k as f64),
            Some(trace.iter().map(|t| t.1).fold(0.0, f64::max)),
        ),
    };
    let tool = ToolFigures::of(frames, dt);
    Metrics {
        plan_length: plan.length,
        tet_edge: band.tet_edge,
        released_tets: found.released_tets,
        trace_faces: trace.len(),
        mean_deviation,
        max_deviation,
        completion,
        mean_depth_error,
        max_depth: depth.iter().copied().fold(0.0, f64::max),
        collateral_volume: found.collateral_volume,
        released_volume: found.released_volume,
        cut_faces: found.cut_faces,
        cut_area: found.cut_area,
        band_volume: plan.length * 2.0 * band.lateral * band.max_depth,
        max_force: tool.max_force,
        mean_force: tool.mean_force,
        strokes: tool.strokes,
        duration: tool.duration,
        depth_profile: plan
            .samples
            .iter()
            .map(|s| s.s)
            .zip(depth.clone())
            .collect(),
        force_series: frames.iter().map(|f| (f.time, f.force)).collect(),
    }
}

/// The tool figures of an attempt's frames.
struct ToolFigures {
    max_force: f64,
    mean_force: f64,
    strokes: usize,
    duration: f64,
}

impl ToolFigures {
    fn of(frames: &[ToolFrame], dt: f64) -> ToolFigures {
        let contact: Vec<usize> = (0..frames.len()).filter(|&i| frames[i].contact).collect();
        let mean_force = match contact.len() {
            0 => 0.0,
            k => contact.iter().map(|&i| frames[i].force).sum::<f64>() / k as f64,
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
        ToolFigures {
            max_force: frames.iter().map(|f| f.force).fold(0.0, f64::max),
            mean_force,
            strokes,
            duration,
        }
    }
}
