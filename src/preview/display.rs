//! Whether a window can be opened at all: winit panics without a display server, so the
//! preview asks first and falls back to headless with a message.

/// Why no window can be opened here, or `None` when one can.
pub fn missing_display() -> Option<&'static str> {
    let unix_desktop = cfg!(any(
        target_os = "linux",
        target_os = "freebsd",
        target_os = "openbsd"
    ));
    if unix_desktop && !env_set("DISPLAY") && !env_set("WAYLAND_DISPLAY") {
        return Some("no display (neither DISPLAY nor WAYLAND_DISPLAY is set)");
    }
    None
}

/// Whether the environment variable `name` is set and not empty.
pub fn env_set(name: &str) -> bool {
    std::env::var_os(name).is_some_and(|s| !s.is_empty())
}
