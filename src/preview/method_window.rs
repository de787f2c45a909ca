//! The preview window for a scene of any method ([`DrawnBody`]): the body drawn with
//! the heat map of its own quantity (spring tension, edge strain, stress), stepped with
//! the scene's own script (the Nakao blade's stroke, the rheology indenter) until the
//! left button takes the tool: then the mouse scalpel cuts (Nakao) or presses (rheology)
//! where it is. Right-drag orbits, middle- or shift+right-drag pans, the wheel zooms,
//! Space plays/pauses, Escape quits. The panel shows a Nakao body's localisation each
//! frame: the level chosen (by the refresh-rate manager under a budget), the free nodes
//! and the loop's time split. `--frames N` steps and draws N frames and closes, printing
//! the body's report summary (what it cut, how deep it was pressed) and the last frame's
//! localisation lines as the panel showed them.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Result, anyhow, bail};
use incise_xr::{Camera, Overlays, RenderSettings, Renderer, View};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use super::camera_input::{CameraInput, KeyAction, preview_camera};
use super::pick::pick_tissue;
use super::scalpel_input::{BladeGeometry, ScalpelFeel, ScalpelInput};
use super::window_gpu::{PanelFrame, WindowGpu};
use crate::pictures::drawn_body::DrawnBody;
use crate::pictures::screenshots::ImageSize;
use crate::sim_body::ToolInput;

/// What `incise preview` asked of a method window.
#[derive(Debug, Clone)]
pub struct MethodWindow {
    /// The scene.
    pub scene: PathBuf,
    /// Step and draw this many frames, then close.
    pub frames: Option<u64>,
    /// Save the last frame here.
    pub screenshot: Option<PathBuf>,
    /// Window size.
    pub size: ImageSize,
}

/// Open the window on `w.scene` and run until it closes; prints the report's summary.
pub fn run(w: MethodWindow) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| anyhow!("cannot open a window: {e}"))?;
    let mut app = App {
        w,
        live: None,
        result: Ok(()),
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("window event loop: {e}"))?;
    if let Some(live) = app.live.take() {
        let lines = live.body.live_lines();
        println!("{}", live.body.close(None)?);
        for line in lines {
            println!("last frame's {line}");
        }
    }
    app.result
}

struct App {
    w: MethodWindow,
    live: Option<Live>,
    result: Result<()>,
}

/// The open window.
struct Live {
    window: Arc<Window>,
    gpu: WindowGpu,
    body: DrawnBody,
    renderer: Renderer,
    egui: egui::Context,
    egui_winit: egui_winit::State,
    camera: Camera,
    home: Camera,
    input: CameraInput,
    scalpel: ScalpelInput,
    /// Whether the mouse has taken the tool from the scene's script.
    hand: bool,
    view: Option<(View, (u32, u32))>,
    cursor: Option<(f64, f64)>,
    playing: bool,
    quitting: bool,
    frames: u64,
    message: String,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.live.is_none() {
            match Live::open(event_loop, &self.w) {
                Ok(l) => self.live = Some(l),
                Err(e) => {
                    self.result = Err(e);
                    event_loop.exit();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(live) = &mut self.live else { return };
        let consumed = live
            .egui_winit
            .on_window_event(&live.window, &event)
            .consumed;
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(s) => live.gpu.resize(s.width, s.height),
            WindowEvent::RedrawRequested => match live.frame(&self.w) {
                Ok(true) => {}
                Ok(false) => event_loop.exit(),
                Err(e) => {
                    self.result = Err(e);
                    event_loop.exit();
                }
            },
            WindowEvent::ModifiersChanged(m) => live.input.set_shift(m.state().shift_key()),
            WindowEvent::MouseInput { state, button, .. } if !consumed => {
                if button == MouseButton::Left {
                    live.scalpel_button(state);
                } else {
                    live.input.button(button, state);
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let h = live.window.inner_size().height as f64;
                live.input
                    .cursor(&mut live.camera, position.x, position.y, h);
                live.cursor = Some((position.x, position.y));
                if let Some((o, d)) = live.cursor_ray().filter(|_| !live.input.dragging()) {
                    live.scalpel.cursor(o, d);
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                live.input.wheel(&mut live.camera, delta)
            }
            WindowEvent::KeyboardInput { event, .. }
                if !consumed && event.state == ElementState::Pressed =>
            {
                match live
                    .input
                    .key(&mut live.camera, &live.home, &event.logical_key)
                {
                    KeyAction::PlayPause => live.playing = !live.playing,
                    KeyAction::Quit => live.quitting = true,
                    KeyAction::None | KeyAction::Fullscreen => {}
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(live) = &self.live {
            live.window.request_redraw();
        }
    }
}

impl Live {
    fn open(event_loop: &ActiveEventLoop, w: &MethodWindow) -> Result<Live> {
        let attrs = Window::default_attributes()
            .with_title("incise preview")
            .with_inner_size(winit::dpi::PhysicalSize::new(w.size.0, w.size.1));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| anyhow!("cannot open a window: {e}"))?,
        );
        let gpu = WindowGpu::new(window.clone())?;
        let body = DrawnBody::open(&w.scene)?;
        let renderer = renderer_for(&gpu, &body);
        let egui = egui::Context::default();
        let egui_winit = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.dev.limits.max_texture_dimension_2d as usize),
        );
        let home = preview_camera(&body.render.mesh);
        let (lo, hi) = body.render.mesh.rest_bounds();
        let top = glam::Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), hi.z);
        let tool = crate::scene::hand_tool::default_tool()?;
        let scalpel = ScalpelInput::new(
            BladeGeometry::of(&tool),
            ScalpelFeel::default(),
            top,
            home.yaw + std::f32::consts::FRAC_PI_2,
        );
        Ok(Live {
            window,
            gpu,
            body,
            renderer,
            egui,
            egui_winit,
            camera: home,
            home,
            input: CameraInput::default(),
            scalpel,
            hand: false,
            view: None,
            cursor: None,
            playing: true,
            quitting: false,
            frames: 0,
            message: String::new(),
        })
    }

    /// The world ray through the cursor, if a frame has been drawn.
    fn cursor_ray(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        let ((view, (w, h)), (x, y)) = (self.view.as_ref()?, self.cursor?);
        Some(view.ray(
            glam::Vec2::new(x as f32, y as f32),
            glam::Vec2::new(*w as f32, *h as f32),
        ))
    }

    /// The left button: down on the tissue takes the tool from the script and engages
    /// it there; up lifts it.
    fn scalpel_button(&mut self, state: ElementState) {
        if state == ElementState::Released {
            self.scalpel.release();
            return;
        }
        let Some((o, d)) = self.cursor_ray() else {
            return;
        };
        let b = &self.body;
        let hit = pick_tissue(o, d, &b.render.mesh, &b.render.cut, b.state().positions);
        if hit.is_some() && !self.hand {
            self.hand = true;
            self.scalpel.take_over(self.scalpel.target_pose());
        }
        if !self.scalpel.press(hit) {
            self.message = "no tissue under the cursor".into();
        }
    }

    /// What moves the tool this frame: the scene's script until the mouse took it.
    fn tool_input(&mut self) -> ToolInput {
        if !self.hand {
            return ToolInput::Script;
        }
        let pose = self.scalpel.advance(self.body.body.frame_dt() as f32);
        ToolInput::Hand {
            pose,
            engaged: self.scalpel.cutting(),
        }
    }

    /// Step (when playing), draw, and save the last frame; `Ok(false)` to close.
    fn frame(&mut self, w: &MethodWindow) -> Result<bool> {
        if self.playing {
            let tool = self.tool_input();
            match self.body.step(&tool) {
                Ok(true) => self.renderer = renderer_for(&self.gpu, &self.body),
                Ok(false) => {}
                Err(e) => {
                    self.playing = false;
                    self.message = format!("solver stopped: {e}");
                }
            }
        }
        let (panel, panel_points) = self.panel();
        let last = self.quitting || w.frames.is_some_and(|n| self.frames + 1 >= n);
        let capture = last && w.screenshot.is_some();
        let settings = RenderSettings {
            overlays: Overlays {
                stress: true,
                ..Overlays::default()
            },
            stress_max: self.body.scale,
            ..RenderSettings::default()
        };
        let (width, height) = self.gpu.size();
        let mut view = self.camera.view(width as f32 / height.max(1) as f32);
        let shift = panel_points * panel.pixels_per_point / width.max(1) as f32;
        view.proj = glam::Mat4::from_translation(glam::Vec3::new(shift, 0.0, 0.0)) * view.proj;
        self.view = Some((view, (width, height)));
        let state = self.body.state();
        let Some(image) =
            self.gpu
                .draw(&mut self.renderer, &state, &settings, &view, panel, capture)?
        else {
            return Ok(true);
        };
        self.frames += 1;
        if let (true, Some(path)) = (capture, &w.screenshot) {
            save(image, path)?;
        }
        Ok(!last)
    }

    /// The side panel: scene, method, heat-map quantity, frame, play/pause.
    fn panel(&mut self) -> (PanelFrame, f32) {
        let input = self.egui_winit.take_egui_input(&self.window);
        let body = &self.body;
        let (method, quantity) = (body.body.method().name(), body.quantity());
        let live_lines = body.live_lines();
        let (mut width, mut playing) = (0.0, self.playing);
        let message = &self.message;
        let out = self.egui.run_ui(input, |ui| {
            let shown = egui::Panel::left("method")
                .default_size(240.0)
                .show(ui, |ui| {
                    ui.heading(format!("{method} body"));
                    ui.label(format!(
                        "frame {}, t = {:.2} s",
                        body.frames(),
                        body.body.time()
                    ));
                    if let Some(q) = quantity {
                        ui.label(format!(
                            "heat map: {} (0 – {:.3e} {})",
                            q.name, body.scale, q.unit
                        ));
                    }
                    for line in &live_lines {
                        ui.label(line.as_str());
                    }
                    ui.checkbox(&mut playing, "play (Space)");
                    ui.small("Left-drag: cut or press · right-drag: orbit · wheel: zoom");
                    if !message.is_empty() {
                        ui.label(message.as_str());
                    }
                });
            width = shown.response.rect.width();
        });
        self.playing = playing;
        self.egui_winit
            .handle_platform_output(&self.window, out.platform_output);
        let jobs = self.egui.tessellate(out.shapes, out.pixels_per_point);
        let frame = PanelFrame {
            jobs,
            textures: out.textures_delta,
            pixels_per_point: out.pixels_per_point,
        };
        (frame, width)
    }
}

/// A renderer for the body's current topology.
fn renderer_for(gpu: &WindowGpu, body: &DrawnBody) -> Renderer {
    let r = &body.render;
    Renderer::new(
        &gpu.dev.device,
        &gpu.dev.queue,
        gpu.format(),
        &r.mesh,
        &r.skin,
    )
}

/// Write the window's captured frame to `path`.
fn save(image: Option<incise_xr::RgbaImage>, path: &Path) -> Result<()> {
    let Some(img) = image else {
        bail!("this window surface cannot be read back for screenshots; use `incise render`");
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    Ok(img.save_png(path)?)
}
