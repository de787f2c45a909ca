//! A stroke: timed tool poses, read from and written to RON
//! (`(poses: [(t: 0.0, position: (x, y, z), rotation: (x, y, z, w)), ...])`, metres,
//! seconds, quaternion in glam's xyzw order), the spans in which the hand held the tool
//! without engaging it (`lifted: [(from, to), ...]`, s; none: engaged throughout), and
//! the tool pose at any time.

use std::path::Path;

use glam::{Quat, Vec3};
use incise_sim::contact::ToolPose;
use incise_sim::ron_file;
use serde::{Deserialize, Serialize};

use crate::error::{FieldError, FileError};
use crate::interpolate::{hermite, slerp};
use crate::ron_text;

/// One key of a stroke: where the tool frame (the blade tip) is at time `t`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseKey {
    /// Time, s.
    pub t: f64,
    /// Tool-frame origin in the world, m.
    pub position: Vec3,
    /// Tool-frame orientation, unit quaternion `(x, y, z, w)`.
    pub rotation: Quat,
}

impl PoseKey {
    /// The key's pose.
    pub fn pose(&self) -> ToolPose {
        ToolPose::new(self.position, self.rotation)
    }
}

/// The file layout of a stroke.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StrokeFile {
    poses: Vec<PoseKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    lifted: Vec<(f64, f64)>,
}

/// A validated stroke: at least two keys, times finite and strictly increasing,
/// positions finite, rotations unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    times: Vec<f64>,
    positions: Vec<Vec3>,
    keys: Vec<PoseKey>,
    /// Spans `[from, to)` in which the tool was held but not engaged, s.
    lifted: Vec<(f64, f64)>,
}

/// How far a key's rotation may be from unit length.
const UNIT_TOLERANCE: f32 = 1e-3;

/// Read and validate a stroke file.
pub fn load_stroke(path: &Path) -> Result<Stroke, FileError> {
    let text = ron_file::read(path)?;
    parse_stroke(&text, path)
}

/// Parse and validate stroke RON text; `path` names it in errors.
pub fn parse_stroke(text: &str, path: &Path) -> Result<Stroke, FileError> {
    let file: StrokeFile = ron_file::parse(text, path)?;
    Stroke::new(file.poses)
        .and_then(|s| s.with_lifted(file.lifted))
        .map_err(|e| ron_text::value_error(text, path, e))
}

impl Stroke {
    /// A stroke from its keys, checked (errors name `poses[i].field`). Rotations within
    /// 1e-3 of unit length are kept exactly as given.
    pub fn new(keys: Vec<PoseKey>) -> Result<Stroke, FieldError> {
        if keys.len() < 2 {
            return Err(FieldError::new(
                "poses",
                format!("a stroke needs at least 2 poses, got {}", keys.len()),
            ));
        }
        for (i, k) in keys.iter().enumerate() {
            if !k.t.is_finite() {
                return Err(FieldError::new(
                    format!("poses[{i}].t"),
                    format!("must be a finite time in s, got {}", k.t),
                ));
            }
            if i > 0 && k.t <= keys[i - 1].t {
                return Err(FieldError::new(
                    format!("poses[{i}].t"),
                    format!(
                        "times must increase strictly: {} s does not come after poses[{}].t = {} s",
                        k.t,
                        i - 1,
                        keys[i - 1].t
                    ),
                ));
            }
            if !k.position.is_finite() {
                return Err(FieldError::new(
                    format!("poses[{i}].position"),
                    format!("must be finite, got {}", k.position),
                ));
            }
            let len = k.rotation.length();
            if !(k.rotation.is_finite() && (len - 1.0).abs() <= UNIT_TOLERANCE) {
                return Err(FieldError::new(
                    format!("poses[{i}].rotation"),
                    format!("not a unit quaternion (length {len})"),
                ));
            }
        }
        Ok(Stroke {
            times: keys.iter().map(|k| k.t).collect(),
            positions: keys.iter().map(|k| k.position).collect(),
            keys,
            lifted: Vec::new(),
        })
    }

    /// The stroke with the tool not engaged (trigger or button up) in the spans
    /// `[from, to)` of `lifted`, s: each finite, `from < to`, in time order without
    /// overlap (errors name `lifted[i]`).
    pub fn with_lifted(mut self, lifted: Vec<(f64, f64)>) -> Result<Stroke, FieldError> {
        for (i, &(from, to)) in lifted.iter().enumerate() {
            let after_previous = i == 0 || lifted[i - 1].1 <= from;
            if !(from.is_finite() && to.is_finite() && from < to && after_previous) {
                return Err(FieldError::new(
                    format!("lifted[{i}]"),
                    format!(
                        "({from}, {to}) must be a finite span from < to, after the previous one"
                    ),
                ));
            }
        }
        self.lifted = lifted;
        Ok(self)
    }

    /// The spans in which the tool was held but not engaged, s.
    pub fn lifted(&self) -> &[(f64, f64)] {
        &self.lifted
    }

    /// Whether time `t` is in a lifted span (the tool held without engaging it).
    pub fn lifted_at(&self, t: f64) -> bool {
        self.lifted.iter().any(|&(from, to)| from <= t && t < to)
    }

    /// Whether the tool is engaged (cuts, grabs, presses) at time `t`: within the keys'
    /// times and outside every lifted span.
    pub fn engaged_at(&self, t: f64) -> bool {
        t >= self.start_time() && t <= self.end_time() && !self.lifted_at(t)
    }

    /// The keys, in time order.
    pub fn keys(&self) -> &[PoseKey] {
        &self.keys
    }

    /// Time of the first key, s.
    pub fn start_time(&self) -> f64 {
        self.times[0]
    }

    /// Time of the last key, s.
    pub fn end_time(&self) -> f64 {
        self.times[self.times.len() - 1]
    }

    /// Duration from the first to the last key, s.
    pub fn duration(&self) -> f64 {
        self.end_time() - self.start_time()
    }

    /// The tool pose at time `t` (s).
    ///
    /// Position: Catmull–Rom through the keys with the key times as knots (non-uniform
    /// Hermite segments, see `interpolate::tangent`); rotation: shortest-arc slerp between
    /// the two keys around `t`. Before the first key and after the last the end pose is
    /// held (a NaN time holds the first). At a key's own time the key is returned
    /// bit for bit.
    pub fn pose_at(&self, t: f64) -> ToolPose {
        let n = self.keys.len();
        if t.is_nan() || t <= self.times[0] {
            return self.keys[0].pose();
        }
        if t >= self.times[n - 1] {
            return self.keys[n - 1].pose();
        }
        // First key strictly after t; t is inside (times[0], times[n-1]).
        let next = self.times.partition_point(|&k| k <= t);
        let i = next - 1;
        if self.times[i] == t {
            return self.keys[i].pose();
        }
        let position = hermite(&self.times, &self.positions, i, t).as_vec3();
        let s = (t - self.times[i]) / (self.times[i + 1] - self.times[i]);
        let rotation = slerp(self.keys[i].rotation, self.keys[i + 1].rotation, s);
        ToolPose::new(position, rotation)
    }

    /// The stroke as pretty RON text (round-trips every f32 and f64 bit for bit).
    pub fn to_ron(&self) -> Result<String, ron::Error> {
        let file = StrokeFile {
            poses: self.keys.clone(),
            lifted: self.lifted.clone(),
        };
        let config = ron::ser::PrettyConfig::new()
            .depth_limit(2)
            .indentor("    ".to_string());
        ron::ser::to_string_pretty(&file, config)
    }

    /// Write the stroke to `path` as pretty RON, atomically (a reader never sees half a
    /// file).
    pub fn save(&self, path: &Path) -> Result<(), FileError> {
        let text = self.to_ron().map_err(|e| FileError::Serialize {
            path: path.into(),
            msg: e.to_string(),
        })?;
        incise_sim::io::write_atomic(path, text.as_bytes()).map_err(FileError::Write)
    }
}
