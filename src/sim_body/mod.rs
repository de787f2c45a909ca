//! The simulated body of each method behind one interface ([`SimBody`]): the XPBD solver
//! on its device, the Nakao mass-spring cutter (frame by frame or at a haptic rate) and
//! the three-element rheological body, side by side; [`open()`] opens a scene's.

pub mod body_view;
pub mod edge_report;
pub mod interface;
pub mod nakao;
pub mod nakao_blade;
pub mod nakao_haptic;
pub mod nakao_open;
pub mod nakao_outcome;
pub mod nakao_surface;
pub mod open;
pub mod outcome;
pub mod recorded;
pub mod rest_cut;
pub mod rheology;
pub mod rheology_open;
pub mod tunables;
pub mod vertex_field;
pub mod xpbd;
pub mod xpbd_device;

pub use body_view::{BodyView, CutShape, CutView, Quantity, Substeps, TetView};
pub use interface::{Fault, OpenOptions, SimBody, SolverParts, StepError, Surface, ToolInput};
pub use open::open;
pub use outcome::Outcome;
pub use rest_cut::{RestCut, RestCutFace};
pub use tunables::Tunables;
pub use xpbd_device::{Body, DeviceChoice, auto_device};
