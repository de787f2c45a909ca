//! Whether a window can be opened at all: winit panics without a display server, so the
//! preview asks first and falls back to headless with a message.

/// Why no window can be opened here, or `None` when one can.
pub fn missing_display() -> Option<&'static str> {
    if cfg!(any(
        target_os = "linux",
        target_os = "freebsd",
        target_os = "openbsd"
    )) {
        let set = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
        if !set("DISPLAY") && !set("WAYLAND_DISPLAY") {
            return Some("no display (neither DISPLAY nor WAYLAND_DISPLAY is set)");
        }
    }
    None
}
