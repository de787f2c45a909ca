//! Shared by the renderer's offscreen tests.

use incise_xr::RenderDevice;

/// A headless render device (lavapipe without a GPU); `None` skips the test, except under
/// `INCISE_REQUIRE_GPU=1` (CI), where a missing adapter fails it.
pub fn device() -> Option<RenderDevice> {
    match RenderDevice::headless() {
        Ok(d) => Some(d),
        Err(e) if std::env::var("INCISE_REQUIRE_GPU").is_ok_and(|v| v == "1") => {
            panic!("INCISE_REQUIRE_GPU=1 but {e}")
        }
        Err(e) => {
            eprintln!("skipping render test: {e}");
            None
        }
    }
}
