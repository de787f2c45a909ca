//! Pictures of a body: offscreen screenshots and what the renderer is told of the scalpel.

pub mod screenshots;
pub mod tool_view;
