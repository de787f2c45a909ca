//! A headset without a runtime: a RON [`script`] of display rate, eyes and
//! timed head, controller and button tracks, played by the [`headset`] that renders both
//! eyes offscreen, so the XR frame loop runs unchanged in tests and on machines without
//! a headset.

pub mod error;
pub mod headset;
pub mod script;

pub use error::ScriptError;
pub use headset::SimulatedHeadset;
pub use script::HeadsetScript;
