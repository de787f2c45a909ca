//! The tension mass-spring model of Nakao et al. 2003 (PHYSICS.md §2): nodes at the tet
//! vertices, a spring (and the node dampers) per tet edge, rest lengths shortened by the
//! tension coefficient so the body starts in a strained equilibrium held by its fixed
//! nodes. Localisation (§2.5): a breadth-first node hierarchy from the tool, frozen nodes
//! beyond level d, and a refresh-rate manager. Cutting lives in [`crate::nakao_cut`].

mod adjacency;
mod axes;
mod god_object;
mod haptic;
mod hierarchy;
mod integrate;
mod local_loop;
mod model;
mod params;
mod refresh;
mod state;
mod stiffness;
mod tension;
mod tet_tensor;
mod tool_coupling;

pub use adjacency::{ElementIndex, Rows};
pub use axes::AxisMask;
pub use god_object::{GodObject, ProxyContact, ProxySurface};
pub use haptic::{HapticConfig, HapticFrame, HapticLoop};
pub use hierarchy::NodeHierarchy;
pub use local_loop::{Clock, LocalLoop, LocalLoopParams, LoopStats, SystemClock};
pub use model::{MassSpringModel, Spring};
pub use params::{MassSpringError, MassSpringParams};
pub use refresh::RefreshRateManager;
pub use state::DynamicState;
pub use stiffness::StiffnessLaw;
pub use tension::Tension;
pub use tet_tensor::TetTensor;
pub use tool_coupling::HapticContact;
pub use tool_coupling::ToolCoupling;

pub(crate) use tet_tensor::edge_frames;

pub(crate) use model::signed_volume;
