//! incise-scalpel: the scalpel as data — tool models read from RON files, strokes (timed
//! tool poses, scripted or recorded) and the contact-force → vibration curve.
//!
//! The crate has no GPU, window or XR code: it turns files into the plain
//! [`incise_sim::contact::ContactTool`] and [`incise_sim::contact::ToolPose`] values the
//! solver consumes (PHYSICS.md §1.5), a triangle mesh the renderer draws, and a vibration
//! amplitude a controller plays.
//!
//! # Units
//! Tool files (`config/tools/*.ron`) give lengths in **millimetres**, as blade drawings
//! do. Everything else — [`Tool`], [`ContactTool`](incise_sim::contact::ContactTool),
//! strokes, render meshes — is SI: metres, seconds, newtons.
//!
//! # Tool frame
//! Right-handed, fixed to the blade:
//! - origin at the blade **tip**;
//! - **+x** along the spine, from the tip toward the handle;
//! - **+z** from the cutting edge toward the spine (blade "up");
//! - **+y** the blade normal (thickness direction); the blade's mid-plane is `y = 0`.
//!
//! The blade outline and the cutting edge are drawn in the x–z plane; the cutting edge is
//! the blade's lower outline. A [`ToolPose`](incise_sim::contact::ToolPose) places this
//! frame in the world, so a stroke's `position` is where the blade tip is.
//!
//! # Contact model
//! [`Tool::contact_tool`] puts cutting spheres evenly (by arc length) along the edge, each
//! centred one radius inside the blade along the edge's in-plane normal, so every sphere
//! is tangent to the edge line from inside and the blade never pushes tissue beyond its
//! real edge. The coarse body (blade flat and handle) is a list of boxes that push but
//! never cut.

#![warn(missing_docs)]

mod error;
mod haptic;
mod incision;
mod interpolate;
mod recorder;
mod render_mesh;
mod ron_text;
mod stroke;
mod stroke_spec;
mod tool;
mod tool_body;
mod tool_spec;
mod triangulate;

pub use error::{FieldError, FileError};
pub use haptic::HapticCurve;
pub use incision::Incision;
pub use recorder::StrokeRecorder;
pub use stroke::{PoseKey, Stroke, load_stroke, parse_stroke};
pub use stroke_spec::{IncisionSpec, ToolStroke};
pub use tool::{Handle, MAX_EDGE_SPHERES, Tool, load_tool, parse_tool};
pub use tool_spec::{BodyBoxSpec, DEFAULT_FRICTION, HandleSpec, SpherePlacement, ToolSpec};
