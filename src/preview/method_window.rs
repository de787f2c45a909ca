//! The preview window for a scene of any method ([`DrawnBody`]): the body drawn with
//! the heat map of its own quantity (spring tension, edge strain, stress), stepped with
//! the scene's own script (the Nakao blade's stroke, the rheology indenter) until the
//! left button takes the tool: then the mouse scalpel cuts (Nakao) or presses (rheology)
//! where it is. Right-drag orbits, middle- or shift+right-drag pans, the wheel zooms,
//! Space plays/pauses, Escape quits. The mouse's scalpel is drawn once it holds the tool;
//! the panel toggles the heat map, resets the scene, saves a screenshot or a `.vtu`. The
//! panel shows a Nakao body's localisation each
//! frame: the level chosen (by the refresh-rate manager under a budget), the free nodes
//! and the loop's time split. `--frames N` steps and draws N frames and closes, printing
//! the body's report summary (what it cut, how deep it was pressed) and the last frame's
//! localisation lines as the panel showed them. With a Nakao exercise the plan is drawn on
//! the tissue and the panel starts and finishes attempts ([`MethodExercise`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use incise_xr::{Overlays, RenderSettings, Renderer, ToolState};
use winit::event::ElementState;

use super::camera_input::preview_camera;
use super::method_exercise::MethodExercise;
use super::pick::pick_tissue;
use super::scalpel_input::{BladeGeometry, ScalpelFeel, ScalpelInput};
use super::window_app::{WindowContent, WindowShell, run_window, save_frame};
use super::window_gpu::WindowGpu;
use crate::pictures::drawn_body::DrawnBody;
use crate::pictures::screenshots::ImageSize;
use crate::pictures::tool_view::pose_matrix;
use crate::sim_body::ToolInput;

/// What `incise preview` asked of a method window.
#[derive(Debug, Clone)]
pub struct MethodWindow {
    /// The scene.
    pub scene: PathBuf,
    /// An exercise on the scene (a Nakao one): its plan drawn, attempts scored.
    pub exercise: Option<PathBuf>,
    /// Step and draw this many frames, then close.
    pub frames: Option<u64>,
    /// Save the last frame here.
    pub screenshot: Option<PathBuf>,
    /// Window size.
    pub size: ImageSize,
}

/// Open the window on `w.scene` and run until it closes; prints the report's summary.
pub fn run(w: MethodWindow) -> Result<()> {
    let Some(live) = run_window(w.size, |shell| Live::open(shell, w))? else {
        return Ok(());
    };
    let lines = live.body.sim.live_lines();
    println!("{}", live.body.sim.close(None)?);
    for line in lines {
        println!("last frame's {line}");
    }
    Ok(())
}

/// The open window.
struct Live {
    shell: WindowShell,
    w: MethodWindow,
    body: DrawnBody,
    renderer: Renderer,
    scalpel: ScalpelInput,
    /// Whether the mouse has taken the tool from the scene's script.
    hand: bool,
    playing: bool,
    /// Whether the heat map is drawn (else the skin).
    heat_map: bool,
    /// Save the next frame drawn as a screenshot (the panel's button).
    capture_next: bool,
    frames: u64,
    message: String,
    /// The open exercise.
    exercise: Option<MethodExercise>,
}

impl WindowContent for Live {
    fn shell(&mut self) -> &mut WindowShell {
        &mut self.shell
    }

    /// Step (when playing), draw, and save the last frame; `Ok(false)` to close.
    fn frame(&mut self) -> Result<bool> {
        if self.playing {
            let tool = self.tool_input();
            match self.body.step(&tool) {
                Ok(remodelled) => {
                    if remodelled {
                        self.renderer = renderer_for(&self.shell.gpu, &self.body);
                    }
                    self.keep_for_attempt(&tool);
                }
                Err(e) => {
                    self.playing = false;
                    self.message = format!("solver stopped: {e}");
                }
            }
        }
        let (panel, panel_points) = self.panel();
        let last = self.shell.quitting || self.w.frames.is_some_and(|n| self.frames + 1 >= n);
        let capture = self.capture_next || (last && self.w.screenshot.is_some());
        let settings = RenderSettings {
            overlays: Overlays {
                stress: self.heat_map,
                ..Overlays::default()
            },
            stress_max: self.body.drawing.scale,
            // The mouse's scalpel once it holds the tool; before, the scene's scripted
            // blade (a Nakao stroke; an indenter is no scalpel).
            tool: ToolState {
                transform: match self.hand {
                    true => Some(self.scalpel.pose()),
                    false => self.body.sim.body.scalpel_pose(),
                }
                .as_ref()
                .map(pose_matrix),
                spheres: vec![],
            },
            lines: self
                .exercise
                .iter()
                .map(|e| e.line(self.body.state().positions))
                .collect(),
            ..RenderSettings::default()
        };
        let view = self.shell.view_beside(panel_points, panel.pixels_per_point);
        let state = self.body.state();
        let gpu = &mut self.shell.gpu;
        let Some(image) = gpu.draw(&mut self.renderer, &state, &settings, &view, panel, capture)?
        else {
            return Ok(true);
        };
        self.frames += 1;
        if capture {
            self.capture_next = false;
            let path = match (&self.w.screenshot, last) {
                (Some(p), true) => p.clone(),
                _ => self.snapshot_path("screenshots", "png"),
            };
            match save_frame(image, &path) {
                Ok(()) => self.message = format!("saved {}", path.display()),
                Err(e) if !last => self.message = format!("{e:#}"),
                Err(e) => return Err(e),
            }
        }
        Ok(!last)
    }

    /// The left button: down on the tissue takes the tool from the script and engages
    /// it there; up lifts it.
    fn left_button(&mut self, state: ElementState) {
        if state == ElementState::Released {
            self.scalpel.release();
            return;
        }
        let Some((o, d)) = self.shell.cursor_ray() else {
            return;
        };
        let b = &self.body;
        let hit = pick_tissue(
            o,
            d,
            &b.drawing.render.mesh,
            &b.drawing.render.cut,
            b.state().positions,
        );
        if hit.is_some() && !self.hand {
            self.hand = true;
            self.scalpel.take_over(self.scalpel.target_pose());
        }
        if !self.scalpel.press(hit) {
            self.message = "no tissue under the cursor".into();
        }
    }

    fn cursor_moved(&mut self) {
        let ray = self.shell.cursor_ray();
        if let Some((o, d)) = ray.filter(|_| !self.shell.input.dragging()) {
            self.scalpel.cursor(o, d);
        }
    }

    fn playing(&mut self) -> &mut bool {
        &mut self.playing
    }
}

impl Live {
    fn open(mut shell: WindowShell, w: MethodWindow) -> Result<Live> {
        let exercise = w
            .exercise
            .as_deref()
            .map(MethodExercise::open)
            .transpose()?;
        let body = DrawnBody::open(&w.scene)?;
        let renderer = renderer_for(&shell.gpu, &body);
        let home = preview_camera(&body.drawing.render.mesh);
        shell.set_home(home);
        let (lo, hi) = body.drawing.render.mesh.rest_bounds();
        let top = glam::Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), hi.z);
        let tool = crate::scene::hand_tool::default_tool()?;
        let mut scalpel = ScalpelInput::new(
            BladeGeometry::of(&tool),
            ScalpelFeel::default(),
            top,
            home.yaw + std::f32::consts::FRAC_PI_2,
        );
        if exercise.is_some() {
            scalpel.take_over(scalpel.target_pose());
        }
        Ok(Live {
            shell,
            w,
            body,
            renderer,
            scalpel,
            // An exercise's blade is the mouse's from the start: the scene's own scripted
            // cut must not open the tissue before the attempt.
            hand: exercise.is_some(),
            playing: true,
            heat_map: true,
            capture_next: false,
            frames: 0,
            message: exercise.as_ref().map_or(String::new(), |e| {
                format!(
                    "exercise {}: cut along the violet line; Start attempt when ready",
                    e.live.exercise.exercise.name
                )
            }),
            exercise,
        })
    }

    /// After a frame stepped with `tool`: the attempt under way keeps its figures and the
    /// blade's pose.
    fn keep_for_attempt(&mut self, tool: &ToolInput) {
        let (Some(e), ToolInput::Hand { pose, engaged }) = (&mut self.exercise, tool) else {
            return;
        };
        if let Err(err) = e.after_step(&self.body.sim, *pose, *engaged) {
            self.message = format!("{err:#}");
        }
    }

    /// Start an attempt: the scene as loaded, the blade in the mouse's hand.
    fn start_attempt(&mut self) {
        let Some(e) = &mut self.exercise else {
            return;
        };
        let started = DrawnBody::open(&self.w.scene).and_then(|mut body| {
            e.start(&mut body.sim)?;
            Ok(body)
        });
        match started {
            Ok(body) => {
                self.body = body;
                self.renderer = renderer_for(&self.shell.gpu, &self.body);
                self.hand = true;
                self.scalpel.take_over(self.scalpel.target_pose());
                self.playing = true;
                self.message = "attempt under way: cut along the line, then Finish".into();
            }
            Err(err) => self.message = format!("{err:#}"),
        }
    }

    /// Finish the attempt under way: scored, saved, its verdict in the panel.
    fn finish_attempt(&mut self) {
        let Some(e) = &mut self.exercise else {
            return;
        };
        let out = Path::new(super::ATTEMPTS_DIR);
        self.message = match e.finish(&self.body.sim, out, Path::new(super::HISTORY_FILE)) {
            Ok(done) => format!(
                "{}\nsaved in {}",
                done.attempt.result.summary(),
                done.dir.display()
            ),
            Err(err) => format!("{err:#}"),
        };
    }

    /// The scene afresh, its script holding the tool again.
    fn reset(&mut self) {
        match DrawnBody::open(&self.w.scene) {
            Ok(body) => {
                self.body = body;
                self.renderer = renderer_for(&self.shell.gpu, &self.body);
                self.hand = false;
                self.scalpel.release();
                self.message = "reset: the scene as loaded".into();
            }
            Err(e) => self.message = format!("{e:#}"),
        }
    }

    /// `dir/<scene>_f<frame>.<ext>`: where the panel's buttons save.
    fn snapshot_path(&self, dir: &str, ext: &str) -> PathBuf {
        let name = self
            .w
            .scene
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy();
        let frame = self.body.sim.frames();
        Path::new(dir).join(format!("{name}_f{frame:05}.{ext}"))
    }

    /// The body as a `.vtu` in `out/preview/` (for ParaView); its path.
    fn save_vtu(&self) -> Result<PathBuf> {
        let path = self.snapshot_path("out/preview", "vtu");
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        self.body.sim.body.write_vtu(&path)?;
        Ok(path)
    }

    /// What moves the tool this frame: the scene's script until the mouse took it.
    fn tool_input(&mut self) -> ToolInput {
        if !self.hand {
            return ToolInput::Script;
        }
        let pose = self.scalpel.advance(self.body.sim.body.frame_dt() as f32);
        ToolInput::Hand {
            pose,
            engaged: self.scalpel.cutting(),
        }
    }

    /// The side panel: scene, method, heat-map quantity, localisation, frame, play/pause.
    fn panel(&mut self) -> (super::window_gpu::PanelFrame, f32) {
        let body = &self.body;
        let (method, quantity) = (body.sim.body.method().name(), body.quantity());
        let live_lines = body.sim.live_lines();
        let (mut width, mut playing, mut heat_map) = (0.0, self.playing, self.heat_map);
        let (mut start, mut finish) = (false, false);
        let [mut reset, mut shot, mut vtu] = [false; 3];
        let attempt = self.exercise.as_ref().map(|e| e.live.running());
        let message = &self.message;
        let frame = self.shell.panel(|ui| {
            let shown = egui::Panel::left("method")
                .default_size(240.0)
                .show(ui, |ui| {
                    ui.heading(format!("{method} body"));
                    ui.label(format!(
                        "frame {}, t = {:.2} s",
                        body.sim.frames(),
                        body.sim.body.time()
                    ));
                    if let Some(q) = quantity {
                        ui.label(format!(
                            "heat map: {} (0 – {:.3e} {})",
                            q.name, body.drawing.scale, q.unit
                        ));
                    }
                    for line in &live_lines {
                        ui.label(line.as_str());
                    }
                    ui.checkbox(&mut playing, "play (Space)");
                    ui.checkbox(&mut heat_map, "heat map");
                    ui.horizontal(|ui| {
                        // An exercise starts over with its Start attempt button.
                        reset = attempt.is_none() && ui.button("Reset").clicked();
                        shot = ui.button("Screenshot").clicked();
                        vtu = ui.button("Save .vtu").clicked();
                    });
                    if let Some(running) = attempt {
                        ui.separator();
                        start = ui.button("Start attempt").clicked();
                        if let Some(frames) = running {
                            ui.label(format!("attempt: {frames} frames"));
                            finish = ui.button("Finish attempt").clicked();
                        }
                    }
                    ui.small("Left-drag: cut or press · right-drag: orbit · wheel: zoom");
                    if !message.is_empty() {
                        ui.label(message.as_str());
                    }
                });
            width = shown.response.rect.width();
        });
        self.playing = playing;
        self.heat_map = heat_map;
        self.capture_next |= shot;
        if reset {
            self.reset();
        }
        if vtu {
            self.message = match self.save_vtu() {
                Ok(path) => format!("saved {}", path.display()),
                Err(e) => format!("{e:#}"),
            };
        }
        if start {
            self.start_attempt();
        }
        if finish {
            self.finish_attempt();
        }
        (frame, width)
    }
}

/// A renderer for the body's current topology.
fn renderer_for(gpu: &WindowGpu, body: &DrawnBody) -> Renderer {
    let r = &body.drawing.render;
    Renderer::new(
        &gpu.dev.device,
        &gpu.dev.queue,
        gpu.format(),
        &r.mesh,
        &r.skin,
    )
}
