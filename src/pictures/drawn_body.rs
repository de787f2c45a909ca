//! A scene of any method as the preview window and the headset draw it: its body with
//! its report ([`RecordedBody`]) and the tet mesh, skin and heat map the renderer draws
//! ([`TetDrawing`], rebuilt when the method's cut changes the topology).

use std::path::Path;

use anyhow::{Context, Result};
use incise_xr::BodyState;

use super::tet_drawing::TetDrawing;
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{Quantity, ToolInput};

/// A body of any method being drawn.
pub struct DrawnBody {
    /// The body and its report.
    pub sim: RecordedBody,
    /// What the renderer draws of it.
    pub drawing: TetDrawing,
}

impl DrawnBody {
    /// Open the scene at `path` (any method; the XPBD solver on the CPU).
    pub fn open(path: &Path) -> Result<DrawnBody> {
        let sim = RecordedBody::open(path)?;
        let drawing = TetDrawing::new(sim.body.tet_view())
            .with_context(|| format!("{}: drawing", path.display()))?;
        Ok(DrawnBody { sim, drawing })
    }

    /// What the heat map shows.
    pub fn quantity(&self) -> Option<Quantity> {
        self.drawing.quantity()
    }

    /// Step one frame with `tool`; whether the topology changed (the renderer must be
    /// built again for the drawing's mesh). A solver failure is returned as text.
    pub fn step(&mut self, tool: &ToolInput) -> Result<bool, String> {
        self.sim.step(tool)?;
        self.drawing
            .update(self.sim.body.tet_view())
            .map_err(|e| format!("{e:#}"))
    }

    /// The state the renderer draws.
    pub fn state(&self) -> BodyState<'_> {
        self.drawing.state()
    }
}
