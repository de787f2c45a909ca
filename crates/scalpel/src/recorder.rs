//! Recording a stroke from live poses (desktop preview, XR controller) for replay.

use incise_sim::contact::ToolPose;

use crate::error::FieldError;
use crate::stroke::{PoseKey, Stroke};

/// Collects timed poses and turns them into a [`Stroke`].
#[derive(Debug, Clone, Default)]
pub struct StrokeRecorder {
    keys: Vec<PoseKey>,
}

impl StrokeRecorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Record the pose at time `t` (s). Rotations are normalised (tracking drift). A
    /// sample that is not later than the previous one, or that is not finite, is refused
    /// and the recording is unchanged.
    pub fn push(&mut self, t: f64, pose: ToolPose) -> Result<(), FieldError> {
        let i = self.keys.len();
        let field = |f: &str| format!("poses[{i}].{f}");
        if !t.is_finite() {
            return Err(FieldError::new(field("t"), format!("not finite: {t}")));
        }
        if let Some(last) = self.keys.last()
            && t <= last.t
        {
            return Err(FieldError::new(
                field("t"),
                format!("{t} s is not after the previous sample at {} s", last.t),
            ));
        }
        if !pose.position.is_finite() {
            return Err(FieldError::new(
                field("position"),
                format!("not finite: {}", pose.position),
            ));
        }
        let len = pose.rotation.length();
        if !(pose.rotation.is_finite() && len > 1e-6) {
            return Err(FieldError::new(
                field("rotation"),
                format!("not a rotation (length {len})"),
            ));
        }
        self.keys.push(PoseKey {
            t,
            position: pose.position,
            rotation: pose.rotation / len,
        });
        Ok(())
    }

    /// The last sample as stored (rotation normalised): the pose a caller drives the
    /// solver with so that a replay of the finished stroke sees the same bits.
    pub fn last(&self) -> Option<PoseKey> {
        self.keys.last().copied()
    }

    /// Number of samples so far.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// Whether nothing has been recorded.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// The recorded stroke (an error if fewer than 2 samples were recorded).
    pub fn finish(self) -> Result<Stroke, FieldError> {
        Stroke::new(self.keys)
    }
}
