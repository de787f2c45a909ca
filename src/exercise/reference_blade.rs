//! The reference stroke of an exercise on a Nakao scene: the scene's straight blade held
//! along the plan's surface normal, its heel just past the target depth, drawn along the plan
//! from end to end (a straight edge has no belly to finish on: it cuts where it is).

use anyhow::{Context, Result};
use glam::{DQuat, DVec3};
use incise_scalpel::{PoseKey, Stroke};

use super::load::LoadedExercise;
use super::reference_style::ReferenceStyle;
use crate::scene::MassSpringScene;
use crate::sim_body::nakao_blade::Blade;

/// Key spacing along the plan, m.
const KEY_SPACING: f64 = 0.001;

/// The reference stroke of `ex`, a Nakao scene with settings `ms`: the tool (the blade's
/// tip, PHYSICS.md §2.3) turned so that the edge stands along the plan's normal, lowered
/// from `style.approach` above the surface until the heel is a quarter of the depth
/// tolerance past the target depth at the plan's start, moved along the plan at `style.speed`, and lifted out at its end.
pub fn blade_reference(
    ex: &LoadedExercise,
    ms: &MassSpringScene,
    style: ReferenceStyle,
) -> Result<Stroke> {
    let edge = Blade::of_stroke(ms.stroke.clone()).edge();
    let length = edge.length();
    // A quarter of the depth tolerance past the target: a heel held exactly on the far
    // surface of a through cut crosses the bottom tets only partly wherever the hand
    // rises by a hair, and the cutter opens no face there (measured in the headset: half
    // the plate's cut surface).
    let depth = (ex.exercise.depth + 0.25 * ex.exercise.tolerance.depth) as f64;
    let speed = style.speed as f64;
    let approach = style.approach as f64;
    let plan = &ex.plan.samples;
    let at = |s: f64| -> (DVec3, DVec3) {
        let i = plan.partition_point(|p| p.s < s).clamp(1, plan.len() - 1);
        let (p, q) = (&plan[i - 1], &plan[i]);
        let u = ((s - p.s) / (q.s - p.s).max(1e-12)).clamp(0.0, 1.0);
        (
            p.point.lerp(q.point, u),
            p.normal.lerp(q.normal, u).normalize(),
        )
    };
    // The tool's origin is the tip: `length` above the heel along the normal.
    let key = |t: f64, s: f64, above: f64| -> PoseKey {
        let (p, n) = at(s);
        PoseKey {
            t,
            position: (p + n * (length - depth + above)).as_vec3(),
            rotation: DQuat::from_rotation_arc(edge / length, n).as_quat(),
        }
    };
    let total = ex.plan.length;
    let leg = (depth + approach) / speed;
    let steps = (total / KEY_SPACING).ceil().max(1.0) as usize;
    let mut keys = vec![key(0.0, 0.0, depth + approach)];
    keys.extend((0..=steps).map(|k| {
        let s = total * k as f64 / steps as f64;
        key(leg + s / speed, s, 0.0)
    }));
    keys.push(key(2.0 * leg + total / speed, total, depth + approach));
    Stroke::new(keys).context("building the blade's reference stroke")
}
