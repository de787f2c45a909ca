//! A reference stroke for an exercise: the scene's scalpel drawn along the plan at the
//! target depth, held as a No. 10 is held to cut with its belly (handle raised from the
//! surface), so that the part of the edge below the surface lies along the plan. What a
//! good attempt looks like, for any exercise; `incise exercise --reference-stroke`. (A
//! Nakao scene's straight blade: `reference_blade`.)

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::{DVec3, Mat3, Quat, Vec3};
use incise_scalpel::{PoseKey, Stroke};

use super::load::LoadedExercise;
use super::reference_blade::blade_reference;
use super::reference_style::ReferenceStyle;
use crate::scene::ModelChoice;

/// Key spacing along the plan, m.
const KEY_SPACING: f64 = 0.001;

/// The blade's edge at one tilt, in the plane of the cut: x along the cut (ahead
/// positive: the handle leads, the tip trails), z up, tip at the origin.
struct TiltedEdge {
    /// Lowest edge height, m (negative: below the tip).
    low: f64,
    /// x of the lowest edge point, m.
    x_low: f64,
    /// Rearmost x of the edge within `depth` of its lowest point (where the part in the
    /// tissue starts when the lowest point is at the target depth), m.
    entry: f64,
}

impl TiltedEdge {
    fn new(edge: &[glam::Vec2], tilt: f64, depth: f64) -> TiltedEdge {
        let pts: Vec<(f64, f64)> = edge
            .iter()
            .map(|p| {
                let (x, z) = (p.x as f64, p.y as f64);
                (
                    x * tilt.cos() - z * tilt.sin(),
                    x * tilt.sin() + z * tilt.cos(),
                )
            })
            .collect();
        let mut dense = Vec::new();
        for w in pts.windows(2) {
            for k in 0..=20 {
                let u = k as f64 / 20.0;
                dense.push((
                    w[0].0 + (w[1].0 - w[0].0) * u,
                    w[0].1 + (w[1].1 - w[0].1) * u,
                ));
            }
        }
        let (x_low, low) = dense
            .iter()
            .copied()
            .fold((0.0, f64::INFINITY), |m, p| if p.1 < m.1 { p } else { m });
        let entry = dense
            .iter()
            .filter(|p| p.1 - low < depth)
            .map(|p| p.0)
            .fold(f64::INFINITY, f64::min);
        TiltedEdge { low, x_low, entry }
    }
}

/// How far ahead along the plan the blade's heading is taken, m.
const HEADING_LOOKAHEAD: f64 = 0.005;

/// Tilt at which the reference stroke finishes, on the tip (degrees).
const FINISH_TILT_DEG: f64 = 75.0;

/// The reference stroke of `ex` with the scene's tool, held as a surgeon holds a No. 10:
/// the blade's lowest edge point at the target depth below the plan (rest coordinates),
/// aimed along it, handle leading and raised `tilt_deg` where it enters (the edge in the
/// tissue starting at the plan's start). The handle then rises steadily to
/// `FINISH_TILT_DEG` (75°), so that the lowest point reaches the plan's end (less half the
/// lateral tolerance, the reach of the cutting spheres) with little edge ahead of it in
/// the tissue ("finishing on the tip"), and the blade lifts out along the surface normal.
pub fn reference_stroke(ex: &LoadedExercise, style: ReferenceStyle) -> Result<Stroke> {
    if !(style.tilt_deg.is_finite() && (0.0..90.0).contains(&style.tilt_deg)) {
        bail!("tilt must be in [0, 90) degrees, got {}", style.tilt_deg);
    }
    if !(style.speed.is_finite() && style.speed > 0.0) {
        bail!("speed must be > 0 m/s, got {}", style.speed);
    }
    if let ModelChoice::MassSpring(ms) = &ex.scene.model {
        return blade_reference(ex, ms, style);
    }
    let spec = ex
        .scene
        .tool
        .as_ref()
        .context("the exercise's scene has no tool")?;
    let tool = crate::scene::load_tool_beside(&ex.scene_path, &spec.file)?;
    let depth = ex.exercise.depth as f64;
    let tilt0 = (style.tilt_deg as f64).to_radians();
    let tilt1 = FINISH_TILT_DEG.to_radians().max(tilt0);
    let at = |tilt: f64| TiltedEdge::new(tool.edge(), tilt, depth);
    let plan = &ex.plan;
    // Point and normal at arc length `s`, continued straight past the plan's ends.
    let point_at = |s: f64| -> (DVec3, DVec3) {
        let smp = &plan.samples;
        let i = smp.partition_point(|p| p.s < s).clamp(1, smp.len() - 1);
        let (p, q) = (&smp[i - 1], &smp[i]);
        let u = (s - p.s) / (q.s - p.s).max(1e-12);
        (
            p.point.lerp(q.point, u),
            if u < 0.5 { p.normal } else { q.normal },
        )
    };
    // The pose with the lowest edge point over plan position `q` at the target depth.
    let pose = |q: f64, tilt: f64| -> (Vec3, Quat) {
        let e = at(tilt);
        let s = q - e.x_low;
        let (tip, n) = point_at(s);
        let ahead = point_at(s + HEADING_LOOKAHEAD).0 - tip;
        let mut h = (ahead - n * ahead.dot(n)).normalize_or_zero();
        if h == DVec3::ZERO {
            h = n.any_orthonormal_vector();
        }
        let x = h * tilt.cos() + n * tilt.sin();
        let z = n * tilt.cos() - h * tilt.sin();
        let y = z.cross(x);
        let rotation = Quat::from_mat3(&Mat3::from_cols(x.as_vec3(), y.as_vec3(), z.as_vec3()));
        ((tip + n * (-e.low - depth)).as_vec3(), rotation.normalize())
    };
    let start = at(tilt0);
    let q0 = start.x_low - start.entry;
    // The lowest point stops short of the end by half the lateral tolerance: the cutting
    // spheres and the tets they release reach that far beyond the edge itself.
    let end = plan.length - 0.5 * ex.exercise.tolerance.lateral as f64;
    // The handle rises steadily from `tilt0` at the entry to `tilt1` at the end. (Raising
    // it only over the last centimetre, just long enough to keep the edge from running
    // past the end, turned the blade fast under load: 4.1 N and a torn face 4.7 mm off
    // the plan on the intestine, against 3.4 N and 2.0 mm this way.)
    let tilt_at = |q: f64| -> f64 {
        let u = ((q - q0) / (end - q0).max(1e-9)).clamp(0.0, 1.0);
        tilt0 + (tilt1 - tilt0) * u
    };
    let rise = |p: Vec3, q: f64| p + (point_at(q).1 * (depth + style.approach as f64)).as_vec3();
    let leg_time = (depth + style.approach as f64) / style.speed as f64;
    let (first, rotation) = pose(q0, tilt0);
    let mut keys = vec![
        PoseKey {
            t: 0.0,
            position: rise(first, q0),
            rotation,
        },
        PoseKey {
            t: leg_time,
            position: first,
            rotation,
        },
    ];
    let q1 = end.max(q0);
    let n = ((q1 - q0) / KEY_SPACING).ceil().max(1.0) as usize;
    for k in 1..=n {
        let q = q0 + (q1 - q0) * k as f64 / n as f64;
        let (position, rotation) = pose(q, tilt_at(q));
        keys.push(PoseKey {
            t: leg_time + (q - q0) / style.speed as f64,
            position,
            rotation,
        });
    }
    let (last, rotation) = pose(q1, tilt1);
    keys.push(PoseKey {
        t: keys[keys.len() - 1].t + leg_time,
        position: rise(last, q1),
        rotation,
    });
    Stroke::new(keys).context("building the reference stroke")
}

/// Load `exercise` and write its reference stroke (handle raised `tilt_deg`) to `out`.
pub fn write_reference_stroke(exercise: &Path, out: &Path, tilt_deg: f32) -> Result<()> {
    let ex = super::load::load_exercise(exercise)?;
    let stroke = reference_stroke(
        &ex,
        ReferenceStyle {
            tilt_deg,
            ..ReferenceStyle::default()
        },
    )
    .with_context(|| format!("{}: reference stroke", exercise.display()))?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    stroke.save(out)?;
    Ok(())
}
