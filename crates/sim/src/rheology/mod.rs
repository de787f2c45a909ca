//! Three-element rheological tissue (PHYSICS.md §3, seed 002): every tet edge is a Voigt
//! unit (spring k, damper c1) in series with a damper c2 that may depend on the force; the
//! Voigt unit's share `a` of the edge length is a state, clamped to `[a_min, a_max]`.
//! Positions, velocities and ratios are integrated with classical RK4 under a computed
//! explicit stability limit. One element gives viscoelastic, plastic and rheological
//! (clay-like) bodies by its parameters alone (presets in `config/rheology.ron`).
//!
//! Equations (1)–(3), (7) and (8) of the seed were lost in its text and are
//! **reconstructed** in PHYSICS.md §3; the code cites them as such.

mod body;
mod closed_form;
mod damper;
mod edge_law;
mod element;
mod error;
mod indenter;
mod material;
mod presets;
mod press;
mod regions;
mod rk4;
mod sag;
mod single;
mod specimen;
mod stability;
mod state;

pub use body::RheologyBody;
pub use closed_form::creep_recovery;
pub use damper::Damper;
pub use element::{ElementParams, ElementResponse};
pub use error::RheologyError;
pub use indenter::{FlatIndenter, PressSchedule};
pub use material::RheologyMaterial;
pub use presets::{PresetError, RheologyPresets};
pub use press::{PressOutcome, PressProtocol, press_and_release};
pub use regions::{MaterialMap, MaterialRegion, RegionShape};
pub use rk4::Rk4;
pub use sag::sag_under_gravity;
pub use single::{CreepSample, CreepTest};
pub use specimen::{Specimen, SpecimenMesh};
pub use stability::{RK4_HALF_DISK_RADIUS, SAFETY, StabilityLimit, stability_limit};
pub use state::RheologyState;
