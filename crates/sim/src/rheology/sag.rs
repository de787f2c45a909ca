//! A block set down on a table under gravity: how far its top sinks over time (the
//! force-dependent damper's purpose, PHYSICS.md §3; seed 002 §6).

use glam::DVec3;

use super::error::RheologyError;
use super::material::RheologyMaterial;
use super::specimen::Specimen;

/// Steps of the gravity ramp.
const RAMP_STEPS: usize = 50;

/// The top centre's depth below its rest height (m) at `samples + 1` equal times over
/// `duration` s, for `material`'s block on the table under gravity `g` (m/s², along −z).
///
/// Gravity rises linearly over the first `ramp` s (the block is set down gently): a sudden
/// load would shake the block and the shaking, not the weight, would load the dampers.
pub fn sag_under_gravity(
    material: &RheologyMaterial,
    specimen: &Specimen,
    g: f64,
    ramp: f64,
    duration: f64,
    samples: usize,
) -> Result<Vec<(f64, f64)>, RheologyError> {
    let mesh = specimen.mesh()?;
    let mut body = mesh.body(*material, 0.0)?;
    let mut out = vec![(0.0, 0.0)];
    let samples = samples.max(1);
    let dt = duration / samples as f64;
    let ramp_dt = ramp / RAMP_STEPS as f64;
    // Ramp steps completed so far; step j (1-based) applies j/RAMP_STEPS of g.
    let mut ramped = if ramp > 0.0 { 0 } else { RAMP_STEPS };
    for k in 1..=samples {
        let target = k as f64 * dt;
        loop {
            let now = body.time();
            if target - now <= 1e-12 {
                break;
            }
            let mut until = target;
            let mut scale = 1.0;
            if ramped < RAMP_STEPS {
                let boundary = (ramped + 1) as f64 * ramp_dt;
                if boundary - now <= 1e-12 {
                    ramped += 1;
                    continue;
                }
                until = until.min(boundary);
                scale = (ramped + 1) as f64 / RAMP_STEPS as f64;
            }
            body.set_gravity(DVec3::new(0.0, 0.0, -g * scale));
            body.advance(until - now)?;
        }
        out.push((body.time(), mesh.centre_depth(&body)));
    }
    Ok(out)
}
