//! Orbit, pan and zoom from the mouse and keyboard: right-drag orbits (the left button
//! is the scalpel's), middle-drag or shift+right-drag pans, the wheel zooms, arrow keys orbit, +/- zoom, R resets
//! the view, F (or F11) toggles fullscreen, Space plays/pauses, Escape quits.

use incise_sim::TetMesh;
use incise_xr::Camera;
use winit::event::{ElementState, MouseButton, MouseScrollDelta};
use winit::keyboard::{Key, NamedKey};

/// What a key press asks of the window beyond the camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyAction {
    /// Nothing beyond the camera.
    None,
    /// Toggle fullscreen.
    Fullscreen,
    /// Play or pause the simulation.
    PlayPause,
    /// Close the window.
    Quit,
}

/// Mouse-drag state of the camera.
#[derive(Debug, Default)]
pub struct CameraInput {
    orbiting: bool,
    panning: bool,
    shift: bool,
    last: Option<(f64, f64)>,
}

impl CameraInput {
    /// A mouse button changed; returns whether the camera takes it.
    pub fn button(&mut self, button: MouseButton, state: ElementState) -> bool {
        let down = state == ElementState::Pressed;
        match button {
            MouseButton::Right => self.orbiting = down,
            MouseButton::Middle => self.panning = down,
            _ => return false,
        }
        true
    }

    /// Whether a drag is moving the camera now.
    pub fn dragging(&self) -> bool {
        self.orbiting || self.panning
    }

    /// Shift is held (turns orbit-drags into pans).
    pub fn set_shift(&mut self, shift: bool) {
        self.shift = shift;
    }

    /// The cursor moved to `(x, y)` in a window `height` pixels high.
    pub fn cursor(&mut self, camera: &mut Camera, x: f64, y: f64, height: f64) {
        if let Some((lx, ly)) = self.last {
            let (dx, dy) = ((x - lx) as f32, (y - ly) as f32);
            let h = height.max(1.0) as f32;
            if self.panning || (self.orbiting && self.shift) {
                camera.pan(-dx / h, dy / h);
            } else if self.orbiting {
                camera.orbit(-dx * 0.01, dy * 0.01);
            }
        }
        self.last = Some((x, y));
    }

    /// A wheel turn: zoom.
    pub fn wheel(&mut self, camera: &mut Camera, delta: MouseScrollDelta) {
        camera.zoom(0.9f32.powf(wheel_steps(delta)));
    }

    /// A key press.
    pub fn key(&mut self, camera: &mut Camera, home: &Camera, key: &Key) -> KeyAction {
        let step = 5f32.to_radians();
        match key {
            Key::Named(NamedKey::ArrowLeft) => camera.orbit(step, 0.0),
            Key::Named(NamedKey::ArrowRight) => camera.orbit(-step, 0.0),
            Key::Named(NamedKey::ArrowUp) => camera.orbit(0.0, step),
            Key::Named(NamedKey::ArrowDown) => camera.orbit(0.0, -step),
            Key::Named(NamedKey::Space) => return KeyAction::PlayPause,
            Key::Named(NamedKey::Escape) => return KeyAction::Quit,
            Key::Named(NamedKey::F11) => return KeyAction::Fullscreen,
            Key::Character(c) => match c.as_str() {
                "+" | "=" => camera.zoom(0.9),
                "-" => camera.zoom(1.0 / 0.9),
                "r" | "R" => *camera = *home,
                "f" | "F" => return KeyAction::Fullscreen,
                _ => {}
            },
            _ => {}
        }
        KeyAction::None
    }
}

/// Wheel notches in a scroll event (pixel deltas count 40 px a notch).
pub fn wheel_steps(delta: MouseScrollDelta) -> f32 {
    match delta {
        MouseScrollDelta::LineDelta(_, y) => y,
        MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
    }
}

/// The preview's start view of `mesh`: the default one, a little farther out (the panel
/// takes room).
pub fn preview_camera(mesh: &TetMesh) -> Camera {
    let mut cam = crate::pictures::screenshots::default_camera(mesh);
    cam.zoom(1.3);
    cam
}
