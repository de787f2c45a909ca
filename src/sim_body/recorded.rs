//! A scene's body of any method with the report of the frames it stepped (the run's
//! schema): what an interactive session (the preview window, the headset, on its thread
//! or in the frame) steps, summarises and writes at the end.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;

use super::{DeviceChoice, OpenOptions, SimBody, ToolInput, open};
use crate::report::localisation::live_lines;
use crate::report::{FrameData, FrameRecord, Report};
use crate::scene::{ModelChoice, load_scene};

/// A body and its report.
pub struct RecordedBody {
    /// The body.
    pub body: Box<dyn SimBody>,
    report: Report,
    /// A mass-spring scene's localisation setting ("whole", "level d", "budget B ms").
    localisation: Option<String>,
}

impl RecordedBody {
    /// Open the scene at `path` (any method; the XPBD solver on the CPU).
    pub fn open(path: &Path) -> Result<RecordedBody> {
        let opts = OpenOptions {
            device: DeviceChoice::Cpu,
            ..OpenOptions::default()
        };
        RecordedBody::open_with(path, &opts)
    }

    /// Open the scene at `path` (any method) as `opts` asks.
    pub fn open_with(path: &Path, opts: &OpenOptions) -> Result<RecordedBody> {
        let scene = load_scene(path)?;
        let (body, report) = open(&scene, path, opts)?;
        let localisation = match &scene.model {
            ModelChoice::MassSpring(ms) => Some(ms.localisation.label()),
            _ => None,
        };
        Ok(RecordedBody {
            body,
            report,
            localisation,
        })
    }

    /// The scalpel a hand or a scripted incision cuts this body with: the body's own (an
    /// XPBD scene's), else the built-in No. 10.
    pub fn scalpel(&self) -> Result<incise_scalpel::Tool> {
        match self.body.solver_parts().and_then(|p| p.tool) {
            Some(t) => Ok(t.clone()),
            None => crate::scene::hand_tool::default_tool(),
        }
    }

    /// The scene's name (its `name` field).
    pub fn scene_name(&self) -> &str {
        &self.report.scene
    }

    /// Frames stepped so far.
    pub fn frames(&self) -> usize {
        self.report.frames.len()
    }

    /// The statistics of the last frame stepped, if any.
    pub fn last_frame(&self) -> Option<&FrameData> {
        self.report.frames.last().map(|f| &f.stats)
    }

    /// A tet body's pose-free work done between frames, before each took its input
    /// (`ahead_ms` summed over the frames: the implicit scheme's refactorisation after
    /// releases); `None` for the other models.
    pub fn ahead_ms(&self) -> Option<f64> {
        if self.report.frames.is_empty() {
            return None;
        }
        self.report
            .frames
            .iter()
            .map(|f| match &f.stats {
                FrameData::Xpbd(s) => Some(s.ahead_ms),
                FrameData::Edges(_) => None,
            })
            .sum()
    }

    /// The last frame's localisation as a live view shows it: the level chosen (by the
    /// refresh-rate manager under a budget) and the loop's time split; empty for other
    /// methods and before the first frame.
    pub fn live_lines(&self) -> Vec<String> {
        match (
            &self.localisation,
            self.report.frames.last().map(|f| &f.stats),
        ) {
            (Some(setting), Some(FrameData::Edges(s))) => live_lines(setting, s),
            _ => Vec::new(),
        }
    }

    /// Step one frame with `tool` and record it. A solver failure is returned as text.
    pub fn step(&mut self, tool: &ToolInput) -> Result<(), String> {
        let t0 = Instant::now();
        let stats = self.body.step(tool).map_err(|e| e.to_string())?;
        self.report.frames.push(FrameRecord {
            stats,
            wall_ms: t0.elapsed().as_secs_f64() * 1e3,
            gpu_ms: None,
            haptic_amplitude: None,
        });
        Ok(())
    }

    /// The body's end-of-run figures in its report (status "completed"), written to
    /// `path` when given; the report's summary line.
    pub fn close(mut self, path: Option<&Path>) -> Result<String> {
        self.body.finish(&mut self.report)?;
        self.report.status = "completed".into();
        if let Some(path) = path {
            self.report.write(path)?;
        }
        Ok(self.report.summary())
    }
}
