//! The settings of a body a user may change while it runs (the preview's material and
//! solver panel): the XPBD material, damping, time integrator (XPBD substeps or the
//! implicit scheme's Newton iterations) and cut rule. A body that has them
//! ([`crate::sim_body::SimBody::tunables`]) applies new ones to its live state, motion,
//! cut and grabs carried over ([`crate::sim_body::SimBody::retune`]).

use incise_sim::contact::CutZone;
use incise_sim::implicit::NewtonParams;

/// Settings a running body takes without starting over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tunables {
    /// Young's modulus, Pa.
    pub youngs_modulus: f32,
    /// Poisson ratio.
    pub poisson_ratio: f32,
    /// Velocity damping, 1/s.
    pub damping: f32,
    /// von Mises cut threshold, Pa (`None`: no cutting).
    pub cut_threshold: Option<f32>,
    /// Where the cut criterion may release tets (the scene's own unless the user changed
    /// it).
    pub cut_zone: CutZone,
    /// The zone "only along the blade's edge" gives (the scene's own `NearEdge`, else
    /// [`crate::scene::hand_tool::edge_zone`] for this mesh; not editable).
    pub edge_zone: CutZone,
    /// Substeps per frame (XPBD).
    pub substeps: u32,
    /// Whether the body runs the implicit scheme (`newton`) rather than XPBD (`substeps`).
    pub implicit: bool,
    /// The implicit scheme's settings: the scene's own, else the defaults.
    pub newton: NewtonParams,
    /// The Poisson ratios the scene's constraint pair can represent (not editable).
    pub poisson_range: (f32, f32),
}
