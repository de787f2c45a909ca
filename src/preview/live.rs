//! What the preview window shows, one content for every method: a scene's body
//! ([`RecordedBody`]) drawn with its own heat map ([`BodyDrawing`]), the mouse's hand on
//! its tool ([`PreviewHand`]), the side panel, and an exercise when one is open. One frame:
//! the hand says where the tool goes, the body steps, the panel runs, the body is drawn.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use incise_xr::{BodyState, RenderSettings, Renderer, ToolState};
use winit::event::{ElementState, MouseScrollDelta};
use winit::keyboard::ModifiersState;

use super::camera_input::{preview_camera, wheel_steps};
use super::frame_times::{FrameTime, FrameTimes};
use super::hand::PreviewHand;
use super::options::{PreviewExercise, PreviewOptions};
use super::panel::{ExerciseInfo, Panel, PanelInfo, ScalpelInfo};
use super::pick::pick_tissue;
use super::scene_list::scene_files;
use super::window_app::{WindowContent, WindowShell, save_frame};
use super::window_gpu::WindowGpu;
use crate::exercise::ToolFrame;
use crate::pictures::body_drawing::BodyDrawing;
use crate::pictures::tool_view::pose_matrix;
use crate::sim_body::recorded::RecordedBody;
use crate::sim_body::{Body, DeviceChoice, OpenOptions};
use incise_sim::gpu::GpuContext;

/// Everything that exists while the window is open.
pub struct Live {
    pub(super) shell: WindowShell,
    pub(super) opts: PreviewOptions,
    /// The scene file.
    pub(super) scene: PathBuf,
    /// Where the body runs (cpu or gpu).
    pub(super) device: DeviceChoice,
    pub(super) body: RecordedBody,
    pub(super) drawing: BodyDrawing,
    pub(super) renderer: Renderer,
    pub(super) hand: PreviewHand,
    pub(super) panel: Panel,
    times: FrameTimes,
    last_frame: Instant,
    frames_drawn: u64,
    pub(super) capture_next: bool,
    /// Whether the left button holds the blade in the tissue.
    left_down: bool,
    /// Ctrl is held (the wheel sets the depth).
    ctrl: bool,
    /// The open exercise.
    pub(super) exercise: Option<PreviewExercise>,
}

/// How the preview opens a scene's body (any method): the solver on `device`, a GPU one
/// on `gpu` (the window's device, so the renderer draws its buffers), and the tool the
/// scene's script's until a hand takes it.
pub fn preview_options(device: DeviceChoice, gpu: Option<GpuContext>) -> OpenOptions {
    OpenOptions {
        device,
        gpu,
        hand: true,
        script_until_taken: true,
        quiet: true,
        ..OpenOptions::default()
    }
}

/// Open the scene at `path` for the window's device `gpu` (the solver on `device`): its
/// body and the drawing of its first frame.
pub(super) fn open_body(
    path: &Path,
    device: DeviceChoice,
    gpu: &WindowGpu,
) -> Result<(RecordedBody, BodyDrawing)> {
    let opts = preview_options(device, Some(gpu.dev.compute_context()));
    let body = RecordedBody::open_with(path, &opts)?;
    let drawing = BodyDrawing::new(body.body.view(None))
        .with_context(|| format!("{}: drawing", path.display()))?;
    Ok((body, drawing))
}

/// The scalpel the mouse holds on `body` drawn as `drawing`: its scene's, else the
/// built-in one, turned toward a camera at `yaw`.
pub(super) fn hand_for(
    body: &RecordedBody,
    drawing: &BodyDrawing,
    yaw: f32,
) -> Result<PreviewHand> {
    let bounds = drawing.mesh_and_skin().0.rest_bounds();
    Ok(PreviewHand::new(body.scalpel()?, body, bounds, yaw))
}

impl Live {
    /// Open the window's content: the exercise's scene or `opts.scene`.
    pub fn open(mut shell: WindowShell, opts: PreviewOptions) -> Result<Live> {
        let device = match opts.device {
            // A software adapter runs the CPU solver faster than its own compute.
            DeviceChoice::Auto => {
                let (pick, why) = crate::sim_body::auto_device(&shell.gpu.dev.info);
                eprintln!("note: {why}");
                pick
            }
            d => d,
        };
        let exercise = opts
            .exercise
            .as_deref()
            .map(PreviewExercise::open)
            .transpose()?;
        let scene = exercise
            .as_ref()
            .map_or(opts.scene.clone(), |e| e.scene_path().to_path_buf());
        let (body, drawing) = open_body(&scene, device, &shell.gpu)?;
        let home = preview_camera(drawing.mesh_and_skin().0);
        shell.set_home(home);
        let mut hand = hand_for(&body, &drawing, home.yaw)?;
        if exercise.is_some() {
            // The mouse holds the blade: the scene's own stroke would cut the plan.
            hand.take_mouse(&body);
        }
        let renderer = renderer_for(&shell.gpu, &drawing, &hand);
        let scene_dir = scene
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        Ok(Live {
            panel: Panel {
                scenes: scene_files(scene_dir),
                playing: true,
                draft: body.body.tunables(),
                device,
                overlays: incise_xr::Overlays {
                    stress: body.body.method().heat_map_first(),
                    ..Default::default()
                },
                message: exercise.as_ref().map_or(String::new(), |e| {
                    format!(
                        "exercise {}: cut along the violet line; Start attempt when ready",
                        e.exercise.exercise.name
                    )
                }),
                stroke_file: "out/preview_stroke.ron".into(),
                exercises: scene_files(&scene_dir.join("exercises")),
                result_card: None,
                show_result: false,
            },
            scene,
            device,
            body,
            drawing,
            renderer,
            hand,
            exercise,
            shell,
            opts,
            times: FrameTimes::default(),
            last_frame: Instant::now(),
            frames_drawn: 0,
            capture_next: false,
            left_down: false,
            ctrl: false,
        })
    }

    /// The line printed when the window closes: frames and what the body did.
    pub fn close(self) -> Result<String> {
        let frames = self.body.frames();
        let outcome = self.body.body.outcome().map(|o| o.summary);
        let lines = self.body.live_lines();
        let ahead = self.body.ahead_ms();
        let mut out = format!("preview of {}: {frames} frames", self.body.scene_name());
        if let Some(o) = outcome {
            out += &format!(", {o}");
        }
        if let Some(ms) = ahead {
            out += &format!("\nwork done between frames, before their input: {ms:.1} ms");
        }
        out += &format!("\n{}", self.body.close(None)?);
        for line in lines {
            out += &format!("\nlast frame's {line}");
        }
        Ok(out)
    }

    /// Put `body` (a scene loaded or reset) in place with its `drawing`, and a renderer
    /// for them.
    pub(super) fn replace_body(&mut self, (body, drawing): (RecordedBody, BodyDrawing)) {
        self.body = body;
        self.drawing = drawing;
        self.renderer = renderer_for(&self.shell.gpu, &self.drawing, &self.hand);
    }

    /// Simulate one frame (kept for the exercise attempt under way); its time, ms.
    pub(super) fn step(&mut self) -> Result<f64, String> {
        let t0 = Instant::now();
        let tool = self
            .hand
            .tool_input(&self.body)
            .map_err(|e| format!("{e:#}"))?;
        self.body.step(&tool)?;
        self.hand.after_step(&self.body);
        if let (Some(e), Some(frame)) = (&mut self.exercise, self.body.last_frame()) {
            e.after_step(ToolFrame::of(frame));
        }
        self.redraw().map_err(|e| format!("{e:#}"))?;
        Ok(t0.elapsed().as_secs_f64() * 1e3)
    }

    /// Draw the body as it is now (after a step or a retune), sharing with the last
    /// drawing what has not changed; a new renderer when the topology or the body changed.
    pub(super) fn redraw(&mut self) -> Result<()> {
        let view = self.body.body.view(self.drawing.cut_view());
        if self.drawing.update(view)? {
            self.renderer = renderer_for(&self.shell.gpu, &self.drawing, &self.hand);
        }
        Ok(())
    }

    /// What the renderer draws this frame besides the body: overlays, heat-map scale,
    /// the scalpel and the exercise's plan.
    fn render_settings(&self) -> RenderSettings {
        let hand_holds = self.hand.holder() != super::hand::Holder::Script;
        let pose = match hand_holds {
            true => Some(self.hand.input.pose()),
            false => self.body.body.scalpel_pose(),
        };
        let spheres = match self.body.body.solver_parts() {
            Some(p) => crate::pictures::tool_view::tool_state(p.body.solver()).spheres,
            None => vec![],
        };
        RenderSettings {
            overlays: self.panel.overlays,
            stress_max: self.drawing.scale(),
            tool: ToolState {
                transform: pose.as_ref().map(pose_matrix),
                spheres,
            },
            lines: self.exercise.iter().map(|e| self.plan_line(e)).collect(),
            ..RenderSettings::default()
        }
    }

    /// The exercise's plan on the tissue as drawn now.
    fn plan_line(&self, e: &PreviewExercise) -> incise_xr::SurfaceLine {
        match &self.drawing {
            BodyDrawing::Cut(c) => e.decal.line_uncut(&c.positions, c.cut.live()),
            BodyDrawing::Tets(_) => e.decal.line(self.drawing.state().positions),
        }
    }

    /// Save a captured frame: the `--screenshot` file at the end, else under
    /// screenshots/.
    fn save_capture(&mut self, image: Option<incise_xr::RgbaImage>, last: bool) -> Result<()> {
        self.capture_next = false;
        let path = match (&self.opts.screenshot, last) {
            (Some(p), true) => p.clone(),
            _ => self.snapshot_path("screenshots", "png"),
        };
        match save_frame(image, &path) {
            Ok(()) => self.panel.message = format!("saved {}", path.display()),
            Err(e) if !last => self.panel.message = format!("{e:#}"),
            Err(e) => return Err(e),
        }
        Ok(())
    }

    /// `dir/<scene>_f<frame>.<ext>`: where the panel's buttons save.
    pub(super) fn snapshot_path(&self, dir: &str, ext: &str) -> PathBuf {
        let stem = self.scene.file_stem().unwrap_or_default();
        let frame = self.body.frames();
        Path::new(dir).join(format!("{}_f{frame:05}.{ext}", stem.to_string_lossy()))
    }

    /// The cursor moved: the blade follows on its plane (not while the camera is dragged,
    /// nor over the panel unless cutting).
    fn scalpel_cursor(&mut self) {
        let shell = &self.shell;
        if shell.input.dragging() || (!self.left_down && shell.egui.is_pointer_over_egui()) {
            return;
        }
        if let Some((o, d)) = self.shell.cursor_ray() {
            self.hand.input.cursor(o, d);
        }
    }
}

impl WindowContent for Live {
    fn shell(&mut self) -> &mut WindowShell {
        &mut self.shell
    }

    /// One frame; `Ok(false)` when the preview should close.
    fn frame(&mut self) -> Result<bool> {
        let now = Instant::now();
        let frame_ms = (now - self.last_frame).as_secs_f64() * 1e3;
        self.last_frame = now;
        let mut sim_ms = 0.0;
        if self.panel.playing {
            match self.step() {
                Ok(ms) => sim_ms = ms,
                Err(e) => {
                    self.panel.playing = false;
                    self.panel.message = format!("solver stopped: {e}");
                }
            }
        }
        let t_render = Instant::now();
        let live = (self.scene.as_path(), &self.body, &self.drawing);
        let info = panel_info(live, &self.hand, self.exercise.as_ref(), &self.times);
        let panel = &mut self.panel;
        let (mut actions, mut panel_points) = (Vec::new(), 0.0);
        let panel_frame = self
            .shell
            .panel(|ui| (actions, panel_points) = panel.ui(ui, &info));
        for a in actions {
            self.act(a)?;
        }
        let opts = &self.opts;
        let last = self.shell.quitting || opts.frames.is_some_and(|n| self.frames_drawn + 1 >= n);
        let capture = self.capture_next || (last && opts.screenshot.is_some());
        let settings = self.render_settings();
        let view = self
            .shell
            .view_beside(panel_points, panel_frame.pixels_per_point);
        let state = body_state(&self.drawing, &self.body);
        let gpu = &mut self.shell.gpu;
        let drawn = gpu.draw(
            &mut self.renderer,
            &state,
            &settings,
            &view,
            panel_frame,
            capture,
        )?;
        if self.panel.playing {
            // The next frame's pose-free work now, before it reads the mouse.
            self.body.body.prepare_next_frame();
        }
        let Some(image) = drawn else {
            return Ok(true);
        };
        self.frames_drawn += 1;
        self.times.push(FrameTime {
            sim_ms,
            render_ms: t_render.elapsed().as_secs_f64() * 1e3,
            frame_ms,
        });
        if capture {
            self.save_capture(image, last)?;
        }
        Ok(!last)
    }

    /// The left button: down on the tissue takes the tool from the script and starts a
    /// cut there; up lifts the blade.
    fn left_button(&mut self, state: ElementState) {
        if state == ElementState::Released {
            self.hand.input.release();
            self.left_down = false;
            return;
        }
        let Some((o, d)) = self.shell.cursor_ray() else {
            return;
        };
        let (mesh, _) = self.drawing.mesh_and_skin();
        let s = self.drawing.state();
        let hit = pick_tissue(o, d, mesh, s.cut, s.positions);
        if hit.is_some() {
            self.hand.take_mouse(&self.body);
        }
        self.left_down = self.hand.input.press(hit);
        if !self.left_down {
            self.panel.message = "no tissue under the cursor".into();
        }
    }

    fn cursor_moved(&mut self) {
        self.scalpel_cursor();
    }

    fn playing(&mut self) -> &mut bool {
        &mut self.panel.playing
    }

    /// With the left button down or Ctrl held the wheel sets the cut depth; else it zooms.
    fn wheel(&mut self, delta: MouseScrollDelta) {
        if self.left_down || self.ctrl {
            self.hand.input.wheel(wheel_steps(delta));
        } else {
            self.shell.input.wheel(&mut self.shell.camera, delta);
        }
    }

    fn modifiers(&mut self, m: ModifiersState) {
        self.ctrl = m.control_key();
    }
}

/// A renderer for the drawing's mesh and skin, with the hand's scalpel.
pub(super) fn renderer_for(gpu: &WindowGpu, drawing: &BodyDrawing, hand: &PreviewHand) -> Renderer {
    let (mesh, skin) = drawing.mesh_and_skin();
    let mut r = Renderer::new(&gpu.dev.device, &gpu.dev.queue, gpu.format(), mesh, skin);
    r.set_tool_mesh(&crate::pictures::tool_view::tool_mesh(&hand.tool));
    r
}

/// The panel's view of the body, the hand and the exercise.
fn panel_info<'a>(
    live: (&'a Path, &RecordedBody, &BodyDrawing),
    hand: &PreviewHand,
    exercise: Option<&PreviewExercise>,
    times: &'a FrameTimes,
) -> PanelInfo<'a> {
    let (scene, recorded, drawing) = live;
    let body = &*recorded.body;
    let status = match recorded.last_frame() {
        Some(f) => body.progress_line(f),
        None => String::new(),
    };
    PanelInfo {
        scene,
        method: body.method().name(),
        frame: recorded.frames() as u64,
        status,
        live_lines: recorded.live_lines(),
        quantity: drawing.quantity(),
        heat_max: drawing.scale(),
        device: body.device(),
        times,
        scalpel: ScalpelInfo::of(hand, body.script_holds_tool()),
        exercise: exercise.map(|e| {
            let ex = &e.exercise.exercise;
            ExerciseInfo {
                name: ex.name.clone(),
                file: e.exercise.path.clone(),
                description: ex.description.clone(),
                depth: (ex.depth, ex.tolerance.depth),
                lateral: ex.tolerance.lateral,
                time_limit: ex.time_limit,
                running: e.running().map(|n| n as f64 * body.frame_dt()),
            }
        }),
    }
}

/// `body`'s state for the renderer as `drawing` has it: a GPU solver on the window's
/// device lends its displacements without a readback.
fn body_state<'a>(drawing: &'a BodyDrawing, body: &'a RecordedBody) -> BodyState<'a> {
    let mut state = drawing.state();
    if let Some(Body::Gpu(g)) = body.body.solver_parts().map(|p| p.body) {
        state.device_displacements = Some(g.displacement_buffer());
    }
    state
}
