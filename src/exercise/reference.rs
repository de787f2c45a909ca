//! A reference stroke for an exercise: the scene's scalpel drawn along the plan at the
//! target depth, held as a No. 10 is held to cut with its belly (handle raised from the
//! surface), so that the part of the edge below the surface lies along the plan. What a
//! good attempt looks like, for any exercise; `incise exercise --reference-stroke`.

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::{DVec3, Mat3, Quat, Vec3};
use incise_scalpel::{PoseKey, Stroke, load_tool};

use super::load::LoadedExercise;

/// Key spacing along the plan, m.
const KEY_SPACING: f64 = 0.001;

/// How the reference stroke holds and moves the blade.
#[derive(Debug, Clone, Copy)]
pub struct ReferenceStyle {
    /// Angle of the blade's spine above the surface, degrees (0: flat, 90: vertical).
    pub tilt_deg: f32,
    /// Tip speed, m/s.
    pub speed: f32,
    /// Height above the surface where the tip starts and finishes, m.
    pub approach: f32,
}

impl Default for ReferenceStyle {
    /// Handle raised 30°, 3 cm/s, 4 mm approach.
    fn default() -> Self {
        ReferenceStyle {
            tilt_deg: 30.0,
            speed: 0.03,
            approach: 0.004,
        }
    }
}

/// The reference stroke of `ex` with the scene's tool: the tip runs along the plan (in
/// rest coordinates, `depth` below it, offset so the lowest edge point is at the target
/// depth) from where the edge first enters the tissue at the plan's start to where its
/// far end in the tissue reaches the plan's end, aimed along the plan.
pub fn reference_stroke(ex: &LoadedExercise, style: ReferenceStyle) -> Result<Stroke> {
    if !(style.tilt_deg.is_finite() && (0.0..90.0).contains(&style.tilt_deg)) {
        bail!("tilt must be in [0, 90) degrees, got {}", style.tilt_deg);
    }
    if !(style.speed.is_finite() && style.speed > 0.0) {
        bail!("speed must be > 0 m/s, got {}", style.speed);
    }
    let spec = ex
        .scene
        .tool
        .as_ref()
        .context("the exercise's scene has no tool")?;
    let scene_dir = ex.scene_path.parent().unwrap_or(Path::new("."));
    let tool = load_tool(&scene_dir.join(&spec.file))?;
    let tilt = (style.tilt_deg as f64).to_radians();
    let depth = ex.exercise.depth as f64;
    // The edge in the blade's plane, tilted: (along the cut, height) from the tip.
    let edge: Vec<(f64, f64)> = tool
        .edge()
        .iter()
        .map(|p| {
            let (x, z) = (p.x as f64, p.y as f64);
            (
                x * tilt.cos() - z * tilt.sin(),
                x * tilt.sin() + z * tilt.cos(),
            )
        })
        .collect();
    let low = edge.iter().map(|e| e.1).fold(f64::INFINITY, f64::min);
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    for w in edge.windows(2) {
        for k in 0..=20 {
            let u = k as f64 / 20.0;
            let (x, z) = (
                w[0].0 + (w[1].0 - w[0].0) * u,
                w[0].1 + (w[1].1 - w[0].1) * u,
            );
            if z - low < depth {
                (a, b) = (a.min(x), b.max(x));
            }
        }
    }
    let lift = -low;
    let plan = &ex.plan;
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
    let pose = |s: f64| -> (Vec3, Quat) {
        let (tip, n) = point_at(s);
        let ahead = point_at(s + (b - a).max(KEY_SPACING)).0 - tip;
        let mut h = (ahead - n * ahead.dot(n)).normalize_or_zero();
        if h == DVec3::ZERO {
            h = n.any_orthonormal_vector();
        }
        let x = h * tilt.cos() + n * tilt.sin();
        let z = n * tilt.cos() - h * tilt.sin();
        let y = z.cross(x);
        let rotation = Quat::from_mat3(&Mat3::from_cols(x.as_vec3(), y.as_vec3(), z.as_vec3()));
        ((tip + n * (lift - depth)).as_vec3(), rotation.normalize())
    };
    let (s0, s1) = (-a, (plan.length - b).max(-a));
    let rise = |p: Vec3, s: f64| p + (point_at(s).1 * (depth + style.approach as f64)).as_vec3();
    let leg_time = (depth + style.approach as f64) / style.speed as f64;
    let (first, rotation) = pose(s0);
    let mut keys = vec![
        PoseKey {
            t: 0.0,
            position: rise(first, s0),
            rotation,
        },
        PoseKey {
            t: leg_time,
            position: first,
            rotation,
        },
    ];
    let n = ((s1 - s0) / KEY_SPACING).ceil() as usize;
    for k in 1..=n {
        let s = s0 + (s1 - s0) * k as f64 / n as f64;
        let (position, rotation) = pose(s);
        keys.push(PoseKey {
            t: leg_time + (s - s0) / style.speed as f64,
            position,
            rotation,
        });
    }
    let (last, rotation) = pose(s1);
    keys.push(PoseKey {
        t: keys[keys.len() - 1].t + leg_time,
        position: rise(last, s1),
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
