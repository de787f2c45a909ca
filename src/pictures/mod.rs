//! Pictures of a body: a body of any method as the renderer draws it, offscreen
//! screenshots (of the XPBD solver, and of any method's tet views) and what the renderer
//! is told of the scalpel.

pub mod body_drawing;
pub mod drawn_body;
pub mod plan_decal;
pub mod render_command;
pub mod run_pictures;
pub mod screenshots;
pub mod tet_drawing;
pub mod tool_view;
pub mod view_pictures;
