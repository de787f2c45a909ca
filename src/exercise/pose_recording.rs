//! The blade's path during a live attempt, recorded one pose per simulated frame at the
//! frame's end from the scene as loaded, so that `incise exercise --stroke` replays it:
//! the headset's controller.

use std::path::Path;

use anyhow::{Result, bail};
use incise_scalpel::StrokeRecorder;
use incise_sim::contact::ToolPose;

use super::live::{AttemptBody, StrokeSource};

/// A stroke being recorded for an attempt.
#[derive(Default)]
pub struct PoseRecording {
    recorder: Option<StrokeRecorder>,
}

impl PoseRecording {
    /// Record the blade at `pose` at attempt time `t`, s, and whether the hand engaged it
    /// (trigger or button down; nothing while not recording).
    pub fn push(&mut self, t: f64, pose: ToolPose, engaged: bool) -> Result<()> {
        if let Some(r) = &mut self.recorder {
            r.push_engaged(t, pose, engaged)?;
        }
        Ok(())
    }

    /// Whether no pose has been recorded (or nothing is being recorded).
    pub fn is_empty(&self) -> bool {
        self.recorder.as_ref().is_none_or(|r| r.is_empty())
    }
}

impl<B: AttemptBody + ?Sized> StrokeSource<B> for PoseRecording {
    fn start_recording(&mut self, body: &mut B) -> Result<()> {
        if body.frame() != 0 {
            bail!("an attempt starts from the scene as loaded (frame 0)");
        }
        self.recorder = Some(StrokeRecorder::new());
        Ok(())
    }

    fn is_recording(&self) -> bool {
        self.recorder.is_some()
    }

    fn save_recording(&mut self, path: &Path) -> Result<()> {
        let Some(r) = self.recorder.take() else {
            bail!("not recording");
        };
        r.finish()?.save(path)?;
        Ok(())
    }

    fn abort_recording(&mut self) {
        self.recorder = None;
    }
}
