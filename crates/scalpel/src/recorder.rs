//! Recording a stroke from live poses (desktop preview, XR controller) for replay.

use incise_sim::contact::ToolPose;

use crate::error::FieldError;
use crate::stroke::{PoseKey, Stroke};

/// Collects timed poses and turns them into a [`Stroke`].
#[derive(Debug, Clone, Default)]
pub struct StrokeRecorder {
    keys: Vec<PoseKey>,
    /// Whether each key's tool was engaged.
    engaged: Vec<bool>,
}

impl StrokeRecorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Record the pose at time `t` (s), the tool engaged. Rotations are normalised
    /// (tracking drift). A sample that is not later than the previous one, or that is not
    /// finite, is refused and the recording is unchanged.
    pub fn push(&mut self, t: f64, pose: ToolPose) -> Result<(), FieldError> {
        self.push_engaged(t, pose, true)
    }

    /// [`StrokeRecorder::push`] with whether the hand engaged the tool (trigger or button
    /// down) at that sample; the finished stroke is lifted where it did not.
    pub fn push_engaged(
        &mut self,
        t: f64,
        pose: ToolPose,
        engaged: bool,
    ) -> Result<(), FieldError> {
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
        self.engaged.push(engaged);
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

    /// The recorded stroke (an error if fewer than 2 samples were recorded), lifted over
    /// each run of samples taken with the tool not engaged.
    pub fn finish(self) -> Result<Stroke, FieldError> {
        let lifted = lifted_spans(&self.keys, &self.engaged);
        Stroke::new(self.keys)?.with_lifted(lifted)
    }
}

/// The spans covering each run of not-engaged samples: from half-way after the engaged
/// sample before it (its own time when it is the first) to half-way before the engaged
/// sample after it (past the last key when there is none), so that a replay asking at a
/// sample's own time, or a hair off it, finds the sample's state.
fn lifted_spans(keys: &[PoseKey], engaged: &[bool]) -> Vec<(f64, f64)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < keys.len() {
        if engaged[i] {
            i += 1;
            continue;
        }
        let first = i;
        while i < keys.len() && !engaged[i] {
            i += 1;
        }
        let from = match first {
            0 => keys[0].t,
            _ => 0.5 * (keys[first - 1].t + keys[first].t),
        };
        let last = keys[i - 1].t;
        let to = keys.get(i).map_or(last + 1.0, |next| 0.5 * (last + next.t));
        spans.push((from, to));
    }
    spans
}
