//! A body of any method as the renderer draws it, from its [`TetView`]: the tet mesh and
//! skin of the current topology (rebuilt when a cut changes the tets; slivers left out),
//! and the heat map of the method's own quantity per drawn tet on a scale that only grows.

use anyhow::Result;
use incise_sim::cutting::CutState;
use incise_sim::mesh::DEGENERATE_REL;
use incise_sim::skin::Skin;
use incise_sim::{RawMesh, TetMesh};
use incise_xr::BodyState;

use crate::sim_body::{Quantity, TetView};

/// What the renderer draws of the body's current topology.
pub struct RenderMesh {
    /// The tets (degenerate ones left out) at the body's positions when it was built.
    pub mesh: TetMesh,
    /// Its boundary as the skin.
    pub skin: Skin,
    /// Every tet live (cut surfaces are the mesh's own boundary).
    pub cut: CutState,
    /// Which of the body's tets each render tet is.
    kept: Vec<usize>,
}

/// The drawing of a body's latest [`TetView`].
pub struct TetDrawing {
    view: TetView,
    /// The renderer's mesh of the current topology.
    pub render: RenderMesh,
    per_tet: Vec<f32>,
    /// Top of the heat-map scale: the largest value seen so far.
    pub scale: f32,
}

impl TetDrawing {
    /// The drawing of `view`.
    pub fn new(view: TetView) -> Result<TetDrawing> {
        let render = render_mesh(&view)?;
        let mut d = TetDrawing {
            view,
            render,
            per_tet: Vec::new(),
            scale: 0.0,
        };
        d.colour();
        Ok(d)
    }

    /// Draw `view` from now on; whether the topology changed (a renderer built on
    /// [`TetDrawing::render`] must be built again).
    pub fn update(&mut self, view: TetView) -> Result<bool> {
        let changed = view.tets != self.view.tets;
        self.view = view;
        if changed {
            self.render = render_mesh(&self.view)?;
        }
        self.colour();
        Ok(changed)
    }

    /// What the heat map shows.
    pub fn quantity(&self) -> Option<Quantity> {
        self.view.quantity
    }

    /// The state the renderer draws.
    pub fn state(&self) -> BodyState<'_> {
        BodyState {
            positions: &self.view.positions,
            device_displacements: None,
            cut: &self.render.cut,
            heat: &self.per_tet,
            pinned: &[],
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
