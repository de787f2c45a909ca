//! A scene of any method as the preview window and the headset draw it: its body behind
//! [`SimBody`], the tet mesh and skin the renderer draws (rebuilt when the method's cut
//! changes the topology), the heat map of the method's own quantity per tet, and the
//! report of the frames stepped (the run's schema), written or summarised at the end.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use incise_xr::BodyState;

use super::tet_drawing::TetDrawing;
use crate::report::localisation::live_lines;
use crate::report::{FrameData, FrameRecord, Report};
use crate::scene::{ModelChoice, load_scene};
use crate::sim_body::{DeviceChoice, OpenOptions, Quantity, SimBody, ToolInput, open};

/// A body of any method being drawn.
pub struct DrawnBody {
    /// The body.
    pub body: Box<dyn SimBody>,
    report: Report,
    /// What the renderer draws of it.
    pub drawing: TetDrawing,
    /// A mass-spring scene's localisation setting ("whole", "level d", "budget B ms").
    localisation: Option<String>,
}

impl DrawnBody {
    /// Open the scene at `path` (any method; the XPBD solver on the CPU).
    pub fn open(path: &Path) -> Result<DrawnBody> {
        let scene = load_scene(path)?;
        let opts = OpenOptions {
            device: DeviceChoice::Cpu,
            ..OpenOptions::default()
        };
        let (body, report) = open(&scene, path, &opts)?;
        let localisation = match &scene.model {
            ModelChoice::MassSpring(ms) => Some(ms.localisation.label()),
            _ => None,
        };
        let drawing = TetDrawing::new(body.tet_view())
            .with_context(|| format!("{}: drawing", path.display()))?;
        Ok(DrawnBody {
            body,
            report,
            drawing,
            localisation,
        })
    }

    /// What the heat map shows.
    pub fn quantity(&self) -> Option<Quantity> {
        self.drawing.quantity()
    }

    /// Frames stepped so far.
    pub fn frames(&self) -> usize {
        self.report.frames.len()
    }

    /// The last frame's localisation as the live view shows it: the level chosen (by the
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

    /// Step one frame with `tool`; whether the topology changed (the renderer must be
    /// built again for the drawing's mesh). A solver failure is returned as text.
    pub fn step(&mut self, tool: &ToolInput) -> Result<bool, String> {
        let t0 = Instant::now();
        let stats = self.body.step(tool).map_err(|e| e.to_string())?;
        self.report.frames.push(FrameRecord {
            stats,
            wall_ms: t0.elapsed().as_secs_f64() * 1e3,
            gpu_ms: None,
            haptic_amplitude: None,
        });
        self.drawing
            .update(self.body.tet_view())
            .map_err(|e| format!("{e:#}"))
    }

    /// The state the renderer draws.
    pub fn state(&self) -> BodyState<'_> {
        self.drawing.state()
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
