//! What a display draws of a live body's frame, whatever the method: the tets of a mesh
//! the method remodels as it cuts ([`TetView`]), or a fixed mesh with its cut state (the
//! XPBD solver's: tets are released, never remodelled), so a display thread can draw a
//! frame the simulation thread published without holding the body.

use std::sync::Arc;

use glam::Vec3;
use incise_sim::TetMesh;
use incise_sim::cutting::CutState;
use incise_sim::skin::Skin;

/// A frame of a body as the display draws it.
#[derive(Clone)]
pub enum BodyView {
    /// A mesh whose tets the method remodels (Nakao, rheology): drawn from its tets.
    Tets(TetView),
    /// A fixed mesh with released tets (XPBD).
    Cut(CutView),
}

/// The fixed mesh of a [`CutView`], the skin embedded in it and its pins, shared by all
/// its frames.
pub struct CutShape {
    /// The tet mesh.
    pub mesh: TetMesh,
    /// The skin drawn over it.
    pub skin: Skin,
    /// Pinned nodes (drawn by the pinned-nodes overlay).
    pub pinned: Vec<u32>,
}

/// A frame of a body with a fixed mesh: positions, the cut and the heat map.
#[derive(Clone)]
pub struct CutView {
    /// The mesh and skin (the same `Arc` for every frame of one body: a new one means a
    /// new body, e.g. after a reset).
    pub shape: Arc<CutShape>,
    /// Node positions, m.
    pub positions: Vec<Vec3>,
    /// Live tets and visible faces (shared between frames until the cut changes).
    pub cut: Arc<CutState>,
    /// von Mises stress per tet, Pa.
    pub von_mises: Vec<f32>,
    /// Full scale of the stress heat map, Pa.
    pub stress_max: f32,
}

/// How many substeps a body's solver runs a frame, where it has the choice (XPBD).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Substeps {
    /// In force now.
    pub now: u32,
    /// The scene's own.
    pub nominal: u32,
    /// The fewest the stability bound allows (at most `nominal`).
    pub fewest: u32,
}

/// The body as tets for the renderer (which draws a tet mesh's skin and colours the
/// heat map per tet).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TetView {
    /// Node positions now, m.
    pub positions: Vec<Vec3>,
    /// The tets (node indices); they change when a method cuts by remodelling.
    pub tets: Vec<[u32; 4]>,
    /// The heat-map quantity per tet (mean over its nodes or the method's own per-tet
    /// value).
    pub per_tet: Vec<f32>,
    /// What [`TetView::per_tet`] is.
    pub quantity: Option<Quantity>,
}

/// The name and unit of the per-vertex quantity a method colours its heat map with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quantity {
    /// What it is, e.g. "von Mises stress", "spring tension", "edge strain".
    pub name: &'static str,
    /// Its unit, e.g. "Pa", "N", "1".
    pub unit: &'static str,
}
