//! Why rendering could not start or finish.

use std::path::PathBuf;

/// A renderer failure, with what the user can do about it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// No adapter: no GPU and no software driver.
    #[error(
        "no GPU adapter for rendering ({0}); install a GPU driver, or mesa-vulkan-drivers and libvulkan1 for the lavapipe software adapter"
    )]
    NoAdapter(String),
    /// The adapter refused a device with the limits the renderer needs.
    #[error("the GPU adapter {adapter} refused a render device: {msg}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// Cause.
        msg: String,
    },
    /// A requested image size the adapter cannot render.
    #[error("cannot render {width}×{height}: {why}")]
    BadSize {
        /// Requested width, pixels.
        width: u32,
        /// Requested height, pixels.
        height: u32,
        /// What is wrong.
        why: String,
    },
    /// An image for the panel quad that cannot be uploaded (the panel keeps its previous
    /// image).
    #[error("panel image {width}×{height}: {why}")]
    PanelImage {
        /// Image width, pixels.
        width: u32,
        /// Image height, pixels.
        height: u32,
        /// What is wrong.
        why: String,
    },
    /// Reading the image back from the device failed.
    #[error("reading the rendered image back failed: {0}")]
    Readback(String),
    /// A PNG could not be read or written.
    #[error("{path}: {msg}")]
    Image {
        /// The file.
        path: PathBuf,
        /// Cause.
        msg: String,
    },
}
