//! A scripted straight incision: approach, plunge to depth, draw along the line, lift out.

use glam::{Quat, Vec3};

use crate::error::FieldError;
use crate::stroke::{PoseKey, Stroke};

/// A straight incision from `start` to `end` at constant speed, the blade held at
/// `rotation` throughout. The blade tip (tool-frame origin):
/// 1. starts `approach` above `start` (along `up`) at `t = 0`,
/// 2. descends to `depth` below `start`,
/// 3. travels parallel to `end − start` to `depth` below `end`,
/// 4. lifts out to `approach` above `end`,
///
/// every leg at `speed`, with keys about every `dt_key` seconds (at least one interval
/// per leg; legs are split evenly). The Catmull–Rom path rounds the three corners
/// slightly: just past a corner the tip may overshoot the corner's line, e.g. pass below
/// `depth`, by at most 4/27 ≈ 15 % of the key spacing `speed × dt_key` (the Hermite
/// segment after a corner starts with part of the previous leg's velocity); a smaller
/// `dt_key` gives sharper corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Incision {
    /// Where the incision starts on the tissue surface, m.
    pub start: Vec3,
    /// Where it ends on the tissue surface, m.
    pub end: Vec3,
    /// Depth below the surface line, m (≥ 0).
    pub depth: f32,
    /// Tool orientation during the whole stroke.
    pub rotation: Quat,
    /// Height above the surface where the tip starts and finishes, m (≥ 0).
    pub approach: f32,
    /// Tip speed on every leg, m/s (> 0).
    pub speed: f32,
    /// Target time between keys, s (> 0).
    pub dt_key: f64,
    /// World "up" (unit; the solver's default gravity is −z, so usually +z).
    pub up: Vec3,
}

impl Incision {
    /// Ok, or the first field out of range.
    pub fn validate(&self) -> Result<(), FieldError> {
        if !self.start.is_finite() {
            return Err(FieldError::new("start", "must be finite"));
        }
        if !self.end.is_finite() {
            return Err(FieldError::new("end", "must be finite"));
        }
        let nonneg = |f: &str, v: f32| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(FieldError::new(
                    f,
                    format!("must be a finite length >= 0 m, got {v}"),
                ))
            }
        };
        nonneg("depth", self.depth)?;
        nonneg("approach", self.approach)?;
        if self.depth + self.approach <= 0.0 && self.start == self.end {
            return Err(FieldError::new(
                "end",
                "the stroke does not move (start = end, depth = approach = 0)",
            ));
        }
        if !(self.speed.is_finite() && self.speed > 0.0) {
            return Err(FieldError::new(
                "speed",
                format!("must be a positive speed in m/s, got {}", self.speed),
            ));
        }
        if !(self.dt_key.is_finite() && self.dt_key > 0.0) {
            return Err(FieldError::new(
                "dt_key",
                format!("must be a positive time in s, got {}", self.dt_key),
            ));
        }
        let len = self.rotation.length();
        if !(self.rotation.is_finite() && (len - 1.0).abs() <= 1e-3) {
            return Err(FieldError::new(
                "rotation",
                format!("not a unit quaternion (length {len})"),
            ));
        }
        if !(self.up.is_finite() && (self.up.length() - 1.0).abs() <= 1e-3) {
            return Err(FieldError::new(
                "up",
                format!("must be a unit vector, got {}", self.up),
            ));
        }
        Ok(())
    }

    /// The corner points of the tip's path: above start, at depth below start, at depth
    /// below end, above end.
    pub fn corners(&self) -> [Vec3; 4] {
        [
            self.start + self.up * self.approach,
            self.start - self.up * self.depth,
            self.end - self.up * self.depth,
            self.end + self.up * self.approach,
        ]
    }

    /// The stroke (validated first).
    pub fn stroke(&self) -> Result<Stroke, FieldError> {
        self.validate()?;
        let corners = self.corners();
        let step = self.speed as f64 * self.dt_key;
        let mut keys = vec![PoseKey {
            t: 0.0,
            position: corners[0],
            rotation: self.rotation,
        }];
        let mut t = 0.0f64;
        for leg in corners.windows(2) {
            let (a, b) = (leg[0], leg[1]);
            let (a64, b64) = (a.as_dvec3(), b.as_dvec3());
            let len = (b64 - a64).length();
            if len == 0.0 {
                continue;
            }
            // (The small margin keeps an exact multiple from gaining an interval to rounding.)
            let n = ((len / step * (1.0 - 1e-9)).ceil() as usize).max(1);
            let dt = len / self.speed as f64 / n as f64;
            for k in 1..=n {
                t += dt;
                let position = if k == n {
                    b
                } else {
                    a64.lerp(b64, k as f64 / n as f64).as_vec3()
                };
                keys.push(PoseKey {
                    t,
                    position,
                    rotation: self.rotation,
                });
            }
        }
        Stroke::new(keys)
    }
}

impl Stroke {
    /// A scripted straight incision; see [`Incision`] for the path and its parameters.
    pub fn incision(incision: &Incision) -> Result<Stroke, FieldError> {
        incision.stroke()
    }
}
