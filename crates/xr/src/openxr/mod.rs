//! The OpenXR mode (issue 7): a Quest 3 over Link (or any OpenXR runtime with Vulkan)
//! shows the organ on a tray in the room; the right controller is the scalpel.
//!
//! Pure frame logic, tested without a runtime: [`pose`] (axes), [`eye`] (view and
//! projection from `XrView`), [`tray`] (placement), [`scalpel_pose`] (controller → blade),
//! [`haptics`],
//! [`lifecycle`] (session states and the frame in flight), [`bindings`], [`controls`] and
//! [`backdrop`] (passthrough, alpha blend or an opaque room).
//! Runtime side: [`runtime`] (loader, instance, headset), [`manifest`] (which runtime), [`vulkan`] (Vulkan through the
//! runtime, wrapped into wgpu), [`swapchain`], [`actions`], [`passthrough`], [`session`]. The frame loop
//! drives any [`headset::Headset`]: the OpenXR session or the [`crate::simulated`] headset,
//! and keeps a [`frame_log`] of every display frame.

pub mod actions;
pub mod backdrop;
pub mod bindings;
pub mod controls;
pub mod error;
pub mod eye;
pub mod frame_log;
pub mod haptics;
pub mod headset;
pub mod lifecycle;
pub mod manifest;
pub mod passthrough;
pub mod pose;
pub mod result_panel;
pub mod runtime;
pub mod scalpel_pose;
pub mod session;
pub mod swapchain;
pub mod tray;
pub mod vulkan;

pub use error::XrError;
pub use headset::{FrameEvent, Headset, HeadsetFrame};
pub use session::XrSession;
