//! Shared by the renderer's offscreen tests.

use incise_xr::RenderDevice;

pub mod masks;

/// A headless render device (lavapipe without a GPU); `None` skips the test (saying why),
/// except where the GPU is required (`INCISE_REQUIRE_GPU=1`, or `CI` set with it unset),
/// where a missing adapter fails it.
pub fn device() -> Option<RenderDevice> {
    incise_test_gate::or_skip(incise_test_gate::Need::Gpu, RenderDevice::headless())
}
