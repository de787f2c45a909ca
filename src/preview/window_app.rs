//! The preview's window driver, one for every kind of content: the winit event loop, the
//! window with its GPU surface, egui and the orbit camera ([`WindowShell`]), and the
//! routing of events — camera drags, wheel and keys to the camera, the left button, the
//! cursor and the frame to the content ([`WindowContent`]: [`super::live::Live`], a
//! body of any method with its panel).

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result, anyhow};
use incise_xr::{Camera, RgbaImage, View};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::ModifiersState;
use winit::window::{Fullscreen, Window, WindowId};

use super::camera_input::{CameraInput, KeyAction};
use super::window_gpu::{PanelFrame, WindowGpu};
use crate::pictures::screenshots::ImageSize;

/// What every preview window has: the window, its GPU, egui and the orbit camera.
pub struct WindowShell {
    /// The window.
    pub window: Arc<Window>,
    /// Its surface and render device.
    pub gpu: WindowGpu,
    /// The panel's egui context.
    pub egui: egui::Context,
    /// egui's winit glue.
    pub egui_winit: egui_winit::State,
    /// The orbit camera.
    pub camera: Camera,
    /// Where R (or the panel's reset) puts the camera.
    pub home: Camera,
    /// Mouse-drag state of the camera.
    pub input: CameraInput,
    /// The last drawn view and its size in pixels (for cursor rays).
    pub view: Option<(View, (u32, u32))>,
    /// Cursor position, physical pixels.
    pub cursor: Option<(f64, f64)>,
    /// Escape was pressed: the next frame is the last.
    pub quitting: bool,
}

impl WindowShell {
    /// Open a window of `size` with its GPU surface and egui; the camera frames a unit box
    /// until the content sets its own ([`WindowShell::set_home`]).
    fn open(event_loop: &ActiveEventLoop, size: ImageSize) -> Result<WindowShell> {
        let attrs = Window::default_attributes()
            .with_title("incise preview")
            .with_inner_size(winit::dpi::PhysicalSize::new(size.0, size.1));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| anyhow!("cannot open a window: {e}"))?,
        );
        let gpu = WindowGpu::new(window.clone())?;
        let egui = egui::Context::default();
        let egui_winit = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.dev.limits.max_texture_dimension_2d as usize),
        );
        let home = Camera::framing(glam::Vec3::ZERO, glam::Vec3::ONE, 0.0, 0.5);
        Ok(WindowShell {
            window,
            gpu,
            egui,
            egui_winit,
            camera: home,
            home,
            input: CameraInput::default(),
            view: None,
            cursor: None,
            quitting: false,
        })
    }

    /// Put the camera at `home` and make it the reset view.
    pub fn set_home(&mut self, home: Camera) {
        self.home = home;
        self.camera = home;
    }

    /// The world ray through the cursor, if a frame has been drawn.
    pub fn cursor_ray(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        let ((view, (w, h)), (x, y)) = (self.view.as_ref()?, self.cursor?);
        Some(view.ray(
            glam::Vec2::new(x as f32, y as f32),
            glam::Vec2::new(*w as f32, *h as f32),
        ))
    }

    /// Run the panel's egui `ui` for this frame: what it drew, ready for the GPU, and the
    /// panel's width in points.
    pub fn panel(&mut self, ui: impl FnMut(&mut egui::Ui)) -> PanelFrame {
        let input = self.egui_winit.take_egui_input(&self.window);
        let out = self.egui.run_ui(input, ui);
        self.egui_winit
            .handle_platform_output(&self.window, out.platform_output);
        PanelFrame {
            jobs: self.egui.tessellate(out.shapes, out.pixels_per_point),
            textures: out.textures_delta,
            pixels_per_point: out.pixels_per_point,
        }
    }

    /// The camera's view for this frame, centred in the part of the window a panel
    /// `panel_points` wide leaves free; kept for cursor rays.
    pub fn view_beside(&mut self, panel_points: f32, pixels_per_point: f32) -> View {
        let (w, h) = self.gpu.size();
        let mut view = self.camera.view(w as f32 / h.max(1) as f32);
        let shift = panel_points * pixels_per_point / w.max(1) as f32;
        view.proj = glam::Mat4::from_translation(glam::Vec3::new(shift, 0.0, 0.0)) * view.proj;
        self.view = Some((view, (w, h)));
        view
    }

    /// The cursor moved to (`x`, `y`): a camera drag follows it.
    fn cursor_moved(&mut self, x: f64, y: f64) {
        let h = self.window.inner_size().height as f64;
        self.input.cursor(&mut self.camera, x, y, h);
        self.cursor = Some((x, y));
    }

    /// F toggles fullscreen, Escape asks for a last frame; the rest (play/pause) is the
    /// content's.
    fn key(&mut self, key: &winit::keyboard::Key) -> KeyAction {
        match self.input.key(&mut self.camera, &self.home, key) {
            KeyAction::Fullscreen => {
                let full = self
                    .window
                    .fullscreen()
                    .is_none()
                    .then_some(Fullscreen::Borderless(None));
                self.window.set_fullscreen(full);
                KeyAction::None
            }
            KeyAction::Quit => {
                self.quitting = true;
                KeyAction::None
            }
            other => other,
        }
    }
}

/// What a preview window shows and does with the events its shell does not take.
pub trait WindowContent {
    /// The window around the content.
    fn shell(&mut self) -> &mut WindowShell;

    /// Step (when playing) and draw one frame; `Ok(false)` to close the window.
    fn frame(&mut self) -> Result<bool>;

    /// The left button (the scalpel's) went down or up.
    fn left_button(&mut self, state: ElementState);

    /// The cursor moved (the shell has its position and the camera drag).
    fn cursor_moved(&mut self);

    /// Whether the simulation plays (Space toggles it).
    fn playing(&mut self) -> &mut bool;

    /// The wheel turned: zoom by default.
    fn wheel(&mut self, delta: MouseScrollDelta) {
        let shell = self.shell();
        shell.input.wheel(&mut shell.camera, delta);
    }

    /// Shift, Ctrl, Alt changed (the shell has taken Shift for panning).
    fn modifiers(&mut self, _: ModifiersState) {}
}

/// Open a window of `size`, make its content with `open` once the event loop runs, and
/// drive it until it closes; the content at the end (`None`: it never opened).
pub fn run_window<C, F>(size: ImageSize, open: F) -> Result<Option<C>>
where
    C: WindowContent,
    F: FnOnce(WindowShell) -> Result<C>,
{
    let event_loop = EventLoop::new().map_err(|e| anyhow!("cannot open a window: {e}"))?;
    let mut app = App {
        size,
        open: Some(open),
        content: None,
        result: Ok(()),
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("window event loop: {e}"))?;
    app.result.map(|()| app.content)
}

/// Write a captured window frame to `path` (its folder made); an error when the surface
/// could not be read back.
pub fn save_frame(image: Option<RgbaImage>, path: &Path) -> Result<()> {
    let Some(img) = image else {
        anyhow::bail!(
            "this window surface cannot be read back for screenshots; use `incise render`"
        );
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    Ok(img.save_png(path)?)
}

struct App<C, F> {
    size: ImageSize,
    open: Option<F>,
    content: Option<C>,
    result: Result<()>,
}

impl<C: WindowContent, F: FnOnce(WindowShell) -> Result<C>> App<C, F> {
    /// Record `e` and close.
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.result = Err(e);
        event_loop.exit();
    }
}

impl<C: WindowContent, F: FnOnce(WindowShell) -> Result<C>> ApplicationHandler for App<C, F> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(open) = self.open.take() else {
            return;
        };
        match WindowShell::open(event_loop, self.size).and_then(open) {
            Ok(c) => self.content = Some(c),
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(content) = &mut self.content else {
            return;
        };
        let shell = content.shell();
        let consumed = shell
            .egui_winit
            .on_window_event(&shell.window, &event)
            .consumed;
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(s) => shell.gpu.resize(s.width, s.height),
            WindowEvent::RedrawRequested => match content.frame() {
                Ok(true) => {}
                Ok(false) => event_loop.exit(),
                Err(e) => self.fail(event_loop, e),
            },
            WindowEvent::ModifiersChanged(m) => {
                shell.input.set_shift(m.state().shift_key());
                content.modifiers(m.state());
            }
            // A release always reaches the content, so a cut never sticks under the panel.
            WindowEvent::MouseInput { state, button, .. }
                if !consumed || state == ElementState::Released =>
            {
                if button == MouseButton::Left {
                    content.left_button(state);
                } else {
                    shell.input.button(button, state);
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                shell.cursor_moved(position.x, position.y);
                content.cursor_moved();
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => content.wheel(delta),
            WindowEvent::KeyboardInput { event, .. }
                if !consumed
                    && event.state == ElementState::Pressed
                    && shell.key(&event.logical_key) == KeyAction::PlayPause =>
            {
                let playing = content.playing();
                *playing = !*playing;
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(c) = &mut self.content {
            c.shell().window.request_redraw();
        }
    }
}
