//! incise-xr: the renderer of incise.
//!
//! One wgpu renderer for the desktop preview, offscreen screenshots and the XR mode: it
//! takes a device and queue, one view per eye and target textures, and knows nothing of
//! windows, headsets or the command line. Per frame it deforms the skin on the GPU from
//! its tet embedding, hides skin triangles of released tets, draws the cut surface in a
//! wet-tissue material, and adds the switchable overlays (von Mises heat map, tet
//! wireframe, tool spheres, pinned nodes), the tool mesh, lines drawn on the tissue
//! surface (planned incisions) and a textured panel quad (result cards), with 4× MSAA into
//! sRGB. It draws a [`BodyState`] (positions, cut state, heat, pinned nodes), whatever
//! method made it.
//!
//! Beside the renderer: [`openxr`], the OpenXR session and its frame logic (poses, tray,
//! controls, lifecycle, the frame log), and [`simulated`], a headset without a runtime
//! that plays a script, for tests and machines without a headset.

pub mod camera;
pub mod colour_map;
pub mod compare;
pub mod device;
pub mod error;
pub mod frame;
mod gpu_skin;
pub mod image_io;
mod node_world;
pub mod offscreen;
pub mod openxr;
mod panel;
mod pipelines;
pub mod renderer;
mod ribbon;
mod scene_buffers;
pub mod shaders;
pub mod simulated;
mod targets;
pub mod tool_mesh;
pub mod vulkan_instance;

pub use camera::{Camera, View};
pub use device::RenderDevice;
pub use error::RenderError;
pub use frame::{
    BodyState, Overlays, RenderSettings, ShadingMode, SurfaceLine, ToolState, UncutBody,
};
pub use image_io::RgbaImage;
pub use offscreen::OffscreenRenderer;
pub use renderer::Renderer;
pub use tool_mesh::ToolMesh;
