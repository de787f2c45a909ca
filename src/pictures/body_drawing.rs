//! A live body of any method as the renderer draws it, frame after frame: a remodelling
//! method's [`TetDrawing`], or a fixed mesh with its cut state as the XPBD solver
//! publishes it; either tells when the renderer built for it must be built again.

use std::sync::Arc;

use anyhow::Result;
use incise_sim::TetMesh;
use incise_sim::skin::Skin;
use incise_xr::BodyState;

use super::tet_drawing::TetDrawing;
use crate::sim_body::xpbd::VON_MISES;
use crate::sim_body::{BodyView, CutView, Quantity};

/// The drawing of a body's latest [`BodyView`].
pub enum BodyDrawing {
    /// A mesh the method remodels, redrawn from its tets.
    Tets(Box<TetDrawing>),
    /// A fixed mesh with released tets.
    Cut(CutView),
}

impl BodyDrawing {
    /// The drawing of `view`.
    pub fn new(view: BodyView) -> Result<BodyDrawing> {
        Ok(match view {
            BodyView::Tets(t) => BodyDrawing::Tets(Box::new(TetDrawing::new(t)?)),
            BodyView::Cut(c) => BodyDrawing::Cut(c),
        })
    }

    /// Draw `view` from now on; whether the renderer must be built again (the topology or
    /// the body changed).
    pub fn update(&mut self, view: BodyView) -> Result<bool> {
        match (&mut *self, view) {
            (BodyDrawing::Tets(d), BodyView::Tets(t)) => d.update(t),
            (BodyDrawing::Cut(c), BodyView::Cut(v)) => {
                let same = Arc::ptr_eq(&c.shape, &v.shape);
                *c = v;
                Ok(!same)
            }
            (_, view) => {
                *self = BodyDrawing::new(view)?;
                Ok(true)
            }
        }
    }

    /// The last fixed-mesh view drawn, to share with the next (a
    /// [`crate::sim_body::SimBody::view`]'s `previous`).
    pub fn cut_view(&self) -> Option<&CutView> {
        match self {
            BodyDrawing::Cut(c) => Some(c),
            BodyDrawing::Tets(_) => None,
        }
    }

    /// The mesh and skin a renderer is built for.
    pub fn mesh_and_skin(&self) -> (&TetMesh, &Skin) {
        match self {
            BodyDrawing::Tets(d) => (&d.render.mesh, &d.render.skin),
            BodyDrawing::Cut(c) => (&c.shape.mesh, &c.shape.skin),
        }
    }

    /// The state the renderer draws.
    pub fn state(&self) -> BodyState<'_> {
        match self {
            BodyDrawing::Tets(d) => d.state(),
            BodyDrawing::Cut(c) => BodyState {
                positions: &c.positions,
                device_displacements: None,
                cut: &c.cut,
                heat: &c.von_mises,
                pinned: &c.shape.pinned,
            },
        }
    }

    /// What the heat map shows.
    pub fn quantity(&self) -> Option<Quantity> {
        match self {
            BodyDrawing::Tets(d) => d.quantity(),
            BodyDrawing::Cut(_) => Some(VON_MISES),
        }
    }

    /// Full scale of the heat map.
    pub fn scale(&self) -> f32 {
        match self {
            BodyDrawing::Tets(d) => d.scale,
            BodyDrawing::Cut(c) => c.stress_max,
        }
    }
}
