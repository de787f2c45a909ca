//! An exercise in the method window, on a Nakao scene (docs/scoring.md, "A cut surface"):
//! the plan drawn on the tissue, an attempt started from the scene as loaded with the
//! mouse blade's pose recorded every frame, finished by scoring the body's cut surface
//! as `incise exercise` scores the recorded stroke, and saved with its report and card.
//! No window needed: tests drive it with a [`RecordedBody`] and poses.

use std::path::Path;

use anyhow::Result;
use glam::Vec3;
use incise_sim::contact::ToolPose;
use incise_xr::SurfaceLine;

use crate::exercise::live::attempt_pictures;
use crate::exercise::{Finished, LiveExercise, PoseRecording, ToolFrame};
use crate::pictures::run_pictures::RunPictures;
use crate::sim_body::recorded::RecordedBody;

/// An exercise open in the method window.
pub struct MethodExercise {
    /// The exercise and its attempt under way.
    pub live: LiveExercise<RunPictures>,
    /// The mouse blade's path during an attempt.
    stroke: PoseRecording,
}

impl MethodExercise {
    /// Open the exercise at `path`.
    pub fn open(path: &Path) -> Result<MethodExercise> {
        Ok(MethodExercise {
            live: LiveExercise::open(path)?,
            stroke: PoseRecording::default(),
        })
    }

    /// Start an attempt on `body`, the exercise's scene as loaded.
    pub fn start(&mut self, body: &mut RecordedBody) -> Result<()> {
        let pictures = attempt_pictures(body, &self.live.decal);
        self.live.start(&mut self.stroke, body, pictures)
    }

    /// After `body` stepped a frame with the blade at `pose` (`engaged`: the button down):
    /// keep the frame's tool figures and the pose, at the frame's end (nothing without an
    /// attempt).
    pub fn after_step(&mut self, body: &RecordedBody, pose: ToolPose, engaged: bool) -> Result<()> {
        let Some(frame) = body.last_frame().filter(|_| self.live.running().is_some()) else {
            return Ok(());
        };
        self.live.after_step(ToolFrame::of(frame));
        self.stroke.push(body.body.time(), pose, engaged)
    }

    /// Finish the attempt on `body`: scored, saved under `out_root`, appended to `history`.
    pub fn finish(
        &mut self,
        body: &RecordedBody,
        out_root: &Path,
        history: &Path,
    ) -> Result<Finished> {
        self.live.finish(&mut self.stroke, body, out_root, history)
    }

    /// The plan on the tissue whose original nodes are at `positions` (the cut appends its
    /// new nodes after them, so the line follows the tissue it was laid on).
    pub fn line(&self, positions: &[Vec3]) -> SurfaceLine {
        self.live.decal.line(positions)
    }
}
