//! A scene of any method as the preview window and the headset draw it: its body behind
//! [`SimBody`], the tet mesh and skin the renderer draws (rebuilt when the method's cut
//! changes the topology), the heat map of the method's own quantity per tet, and the
//! report of the frames stepped (the run's schema), written or summarised at the end.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use incise_sim::cutting::CutState;
use incise_sim::mesh::DEGENERATE_REL;
use incise_sim::skin::Skin;
use incise_sim::{RawMesh, TetMesh};
use incise_xr::BodyState;

use crate::report::localisation::live_lines;
use crate::report::{FrameData, FrameRecord, Report};
use crate::scene::{ModelChoice, load_scene};
use crate::sim_body::{DeviceChoice, OpenOptions, Quantity, SimBody, TetView, ToolInput, open};

/// What the renderer draws of the body's current topology.
pub struct RenderMesh {
    /// The tets (degenerate ones left out) at the body's reference positions.
    pub mesh: TetMesh,
    /// Its boundary as the skin.
    pub skin: Skin,
    /// Every tet live (cut surfaces are the mesh's own boundary).
    pub cut: CutState,
    /// Which of the body's tets each render tet is.
    kept: Vec<usize>,
}

/// A body of any method being drawn.
pub struct DrawnBody {
    /// The body.
    pub body: Box<dyn SimBody>,
    report: Report,
    view: TetView,
    /// The renderer's mesh of the current topology.
    pub render: RenderMesh,
    per_tet: Vec<f32>,
    /// Top of the heat-map scale: the largest value seen so far.
    pub scale: f32,
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
        let view = body.tet_view();
        let render = render_mesh(&view).with_context(|| format!("{}: drawing", path.display()))?;
        let mut m = DrawnBody {
            body,
            report,
            view,
            render,
            per_tet: Vec::new(),
            scale: 0.0,
            localisation,
        };
        m.colour();
        Ok(m)
    }

    /// What the heat map shows.
    pub fn quantity(&self) -> Option<Quantity> {
        self.view.quantity
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

    /// The heat-map value of each render tet, and the scale's top.
    fn colour(&mut self) {
        self.per_tet = self
            .render
            .kept
            .iter()
            .map(|&t| self.view.per_tet[t])
            .collect();
        let top = self.per_tet.iter().copied().fold(0.0, f32::max);
        self.scale = self.scale.max(top).max(f32::MIN_POSITIVE);
    }

    /// Step one frame with `tool`; whether the topology changed (the renderer must be
    /// built again for [`DrawnBody::render`]). A solver failure is returned as text.
    pub fn step(&mut self, tool: &ToolInput) -> Result<bool, String> {
        let t0 = Instant::now();
        let stats = self.body.step(tool).map_err(|e| e.to_string())?;
        self.report.frames.push(FrameRecord {
            stats,
            wall_ms: t0.elapsed().as_secs_f64() * 1e3,
            gpu_ms: None,
            haptic_amplitude: None,
        });
        let view = self.body.tet_view();
        let changed = view.tets != self.view.tets;
        self.view = view;
        if changed {
            self.render = render_mesh(&self.view).map_err(|e| format!("{e:#}"))?;
        }
        self.colour();
        Ok(changed)
    }

    /// The state the renderer draws.
    pub fn state(&self) -> BodyState<'_> {
        BodyState {
            positions: &self.view.positions,
            device_displacements: None,
            cut: &self.render.cut,
            von_mises: &self.per_tet,
            pinned: &[],
        }
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

/// The renderer's mesh of `view`: its tets at the nodes' positions now, degenerate ones
/// (a cut can leave slivers) left out.
fn render_mesh(view: &TetView) -> Result<RenderMesh> {
    let p = &view.positions;
    let kept: Vec<usize> = (0..view.tets.len())
        .filter(|&t| {
            let [a, b, c, d] = view.tets[t].map(|i| p[i as usize].as_dvec3());
            let (e1, e2, e3) = (b - a, c - a, d - a);
            let mean = [e1, e2, e3, c - b, d - b, d - c]
                .iter()
                .map(|e| e.length())
                .sum::<f64>()
                / 6.0;
            (e1.dot(e2.cross(e3)) / 6.0).abs() >= 2.0 * DEGENERATE_REL * mean.powi(3)
        })
        .collect();
    let (mesh, _) = TetMesh::from_raw(RawMesh {
        positions: p.clone(),
        tets: kept.iter().map(|&t| view.tets[t]).collect(),
        warnings: Vec::new(),
        boundary_faces: None,
    })?;
    let skin = Skin::from_boundary(&mesh);
    let cut = CutState::new(&mesh);
    Ok(RenderMesh {
        mesh,
        skin,
        cut,
        kept,
    })
}
