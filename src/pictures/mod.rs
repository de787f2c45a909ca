//! Pictures of a body: a body of any method as the renderer draws it, offscreen
//! screenshots and what the renderer is told of the scalpel.

pub mod drawn_body;
pub mod screenshots;
pub mod tool_view;
