//! `incise preview`: the desktop window (winit) with the incise-xr renderer, an egui
//! side panel, orbit/pan/zoom and the mouse scalpel (left-drag cuts, see
//! [`scalpel_input`]). `--frames N` renders N frames and exits (for tests and scripts);
//! `--screenshot FILE` saves the window's last frame (also when Escape closes it).
//! `--exercise FILE` opens an exercise ([`LiveExercise`]): its plan drawn on the tissue,
//! attempts scored live and saved.

mod camera_input;
pub mod display;
mod frame_times;
pub mod hand_tool;
pub mod method_exercise;
pub mod method_window;
mod panel;
pub mod pick;
pub mod scalpel_input;
mod session;
mod window_app;
mod window_gpu;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use incise_xr::{BodyState, RenderSettings, Renderer};
use winit::event::{ElementState, MouseScrollDelta};
use winit::keyboard::ModifiersState;

use crate::pictures::screenshots::{ImageSize, Screenshots};
use crate::sim_body::xpbd::stress_scale;
use crate::sim_body::{Body, DeviceChoice};

use crate::exercise::live::ATTEMPT_PICTURE;
use crate::exercise::{LiveExercise, ToolFrame};
use camera_input::{preview_camera, wheel_steps};
use frame_times::{FrameTime, FrameTimes};
use panel::{Action, ExerciseInfo, Panel, PanelInfo, ScalpelInfo};
use session::{Session, scene_files};
use window_app::{WindowContent, WindowShell, run_window, save_frame};

/// Options of `incise preview`.
#[derive(Debug, Clone)]
pub struct PreviewOptions {
    /// Scene to open.
    pub scene: PathBuf,
    /// Render this many frames, then exit.
    pub frames: Option<u64>,
    /// Save the window's last frame here (PNG) when exiting.
    pub screenshot: Option<PathBuf>,
    /// Where the solver runs (auto: the render device's GPU when it is not a software one).
    pub device: DeviceChoice,
    /// Window size.
    pub size: ImageSize,
    /// Open this exercise (its scene instead of `scene`).
    pub exercise: Option<PathBuf>,
}

/// Where the preview saves exercise attempts, one folder each.
pub const ATTEMPTS_DIR: &str = "out/exercises";

/// The results history preview attempts are appended to (`incise exercise`'s default).
pub const HISTORY_FILE: &str = "results/history.jsonl";

/// Open the preview window and run until it is closed (or `--frames` are done).
pub fn run(opts: PreviewOptions) -> Result<()> {
    if let Some(why) = display::missing_display() {
        bail!("{why}: the preview needs a window; use `incise run` or `incise render` headless");
    }
    let scene = match &opts.exercise {
        Some(e) => crate::exercise::exercise_scene(e)?,
        None => opts.scene.clone(),
    };
    if !is_xpbd(&scene)? {
        return method_window::run(method_window::MethodWindow {
            scene,
            exercise: opts.exercise,
            frames: opts.frames,
            screenshot: opts.screenshot,
            size: opts.size,
        });
    }
    let Some(live) = run_window(opts.size, |shell| Live::open(shell, opts))? else {
        return Ok(());
    };
    let solver = live.session.body.solver();
    println!(
        "preview of {}: {} frames, {} tets released",
        live.session.name(),
        solver.frame(),
        solver.cut().released_count()
    );
    Ok(())
}

/// Whether the scene at `path` runs the XPBD method (the full preview with its panel of
/// solver settings, exercises and stroke recording); other methods get a
/// [`method_window`] (with a Nakao scene's exercise).
fn is_xpbd(path: &Path) -> Result<bool> {
    let scene = crate::scene::load_scene(path)?;
    Ok(matches!(scene.model, crate::scene::ModelChoice::Xpbd))
}

/// Everything that exists while the window is open.
struct Live {
    shell: WindowShell,
    opts: PreviewOptions,
    session: Session,
    renderer: Renderer,
    panel: Panel,
    times: FrameTimes,
    last_frame: Instant,
    frames_drawn: u64,
    capture_next: bool,
    /// Whether the left button holds the blade in the tissue.
    left_down: bool,
    /// Ctrl is held (the wheel sets the depth).
    ctrl: bool,
    /// The open exercise.
    exercise: Option<LiveExercise>,
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
        let solver = self.session.body.solver();
        let info = PanelInfo {
            scene: &self.session.path,
            frame: solver.frame(),
            released: solver.cut().released_count(),
            max_stress: solver.von_mises().iter().copied().fold(0.0, f32::max),
            stress_max: stress_scale(solver),
            device: self.session.body.device(),
            times: &self.times,
            scalpel: ScalpelInfo::of(&self.session.hand),
            exercise: self.exercise.as_ref().map(|e| {
                let ex = &e.exercise.exercise;
                ExerciseInfo {
                    name: ex.name.clone(),
                    file: e.exercise.path.clone(),
                    description: ex.description.clone(),
                    depth: (ex.depth, ex.tolerance.depth),
                    lateral: ex.tolerance.lateral,
                    time_limit: ex.time_limit,
                    running: e
                        .running()
                        .map(|n| n as f64 * solver.params().frame_dt as f64),
                }
            }),
        };
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
        let solver = self.session.body.solver();
        let mut state = BodyState::of_solver(solver, &self.session.pinned);
        if let Body::Gpu(g) = &self.session.body {
            state.device_displacements = Some(g.displacement_buffer());
        }
        let settings = RenderSettings {
            overlays: self.panel.overlays,
            stress_max: stress_scale(solver),
            tool: crate::pictures::tool_view::tool_state(solver),
            lines: self
                .exercise
                .iter()
                .map(|e| e.decal.line_uncut(solver.positions(), solver.cut().live()))
                .collect(),
            ..RenderSettings::default()
        };
        let view = self
            .shell
            .view_beside(panel_points, panel_frame.pixels_per_point);
        let drawn = self.shell.gpu.draw(
            &mut self.renderer,
            &state,
            &settings,
            &view,
            panel_frame,
            capture,
        )?;
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
            self.capture_next = false;
            let path = match (&self.opts.screenshot, last) {
                (Some(p), true) => p.clone(),
                _ => PathBuf::from("screenshots").join(format!(
                    "{}_f{:05}.png",
                    self.session.name(),
                    self.session.body.solver().frame()
                )),
            };
            match save_frame(image, &path) {
                Ok(()) => self.panel.message = format!("saved {}", path.display()),
                Err(e) if !last => self.panel.message = format!("{e:#}"),
                Err(e) => return Err(e),
            }
        }
        Ok(!last)
    }

    /// The left button: down on the tissue starts a cut there (the mouse takes the blade
    /// from the scene's stroke), up lifts the blade.
    fn left_button(&mut self, state: ElementState) {
        if state == ElementState::Released {
            self.session.hand.input.release();
            self.left_down = false;
            return;
        }
        let Some((o, d)) = self.shell.cursor_ray() else {
            return;
        };
        let solver = self.session.body.solver();
        let hit = pick::pick_tissue(o, d, solver.mesh(), solver.cut(), solver.positions());
        let (frame, dt) = (solver.frame(), solver.params().frame_dt as f64);
        if hit.is_some() {
            self.session.hand.take_mouse(frame, dt);
        }
        self.left_down = self.session.hand.input.press(hit);
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
            self.session.hand.input.wheel(wheel_steps(delta));
        } else {
            self.shell.input.wheel(&mut self.shell.camera, delta);
        }
    }

    fn modifiers(&mut self, m: ModifiersState) {
        self.ctrl = m.control_key();
    }
}

impl Live {
    fn open(mut shell: WindowShell, opts: PreviewOptions) -> Result<Live> {
        let gpu = &shell.gpu;
        let device = match opts.device {
            // A software adapter runs the CPU solver faster than its own compute.
            DeviceChoice::Auto => {
                let (pick, why) = crate::sim_body::auto_device(&gpu.dev.info);
                eprintln!("note: {why}");
                pick
            }
            d => d,
        };
        let exercise = opts
            .exercise
            .as_deref()
            .map(LiveExercise::open)
            .transpose()?;
        let scene = exercise
            .as_ref()
            .map_or(opts.scene.clone(), |e| e.scene_path().to_path_buf());
        let mut session = Session::load(&scene, device, &gpu.dev)?;
        if exercise.is_some() {
            // The mouse holds the blade: the scene's own stroke would cut the plan.
            session
                .hand
                .take_mouse(0, session.body.solver().params().frame_dt as f64);
        }
        let mut renderer = Renderer::new(
            &gpu.dev.device,
            &gpu.dev.queue,
            gpu.format(),
            session.body.solver().mesh(),
            &session.skin,
        );
        renderer.set_tool_mesh(&crate::pictures::tool_view::tool_mesh(&session.hand.tool));
        shell.set_home(preview_camera(session.body.solver().mesh()));
        let scene_dir = scene
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        Ok(Live {
            panel: Panel {
                scenes: scene_files(scene_dir),
                playing: true,
                draft: session.params,
                device,
                overlays: Default::default(),
                message: String::new(),
                stroke_file: "out/preview_stroke.ron".into(),
                exercises: scene_files(&scene_dir.join("exercises")),
                result_card: None,
                show_result: false,
            },
            exercise,
            shell,
            opts,
            session,
            renderer,
            times: FrameTimes::default(),
            last_frame: Instant::now(),
            frames_drawn: 0,
            capture_next: false,
            left_down: false,
            ctrl: false,
        })
    }

    /// The cursor moved: the blade follows on its plane (not while the camera is dragged,
    /// nor over the panel unless cutting).
    fn scalpel_cursor(&mut self) {
        let shell = &self.shell;
        if shell.input.dragging() || (!self.left_down && shell.egui.is_pointer_over_egui()) {
            return;
        }
        if let Some((o, d)) = self.shell.cursor_ray() {
            self.session.hand.input.cursor(o, d);
        }
    }

    /// Simulate one frame (kept for the exercise attempt under way); its time, ms.
    fn step(&mut self) -> Result<f64, String> {
        let (stats, ms) = self.session.step()?;
        if let Some(e) = &mut self.exercise {
            e.after_step(ToolFrame::of_xpbd(&stats));
        }
        Ok(ms)
    }

    /// Open the scene at `path` in place of the current one.
    fn load_scene(&mut self, path: &Path) -> Result<()> {
        let dev = &self.shell.gpu.dev;
        let s = Session::load(path, self.session.device, dev)?;
        self.renderer = Renderer::new(
            &dev.device,
            &dev.queue,
            self.shell.gpu.format(),
            s.body.solver().mesh(),
            &s.skin,
        );
        self.renderer
            .set_tool_mesh(&crate::pictures::tool_view::tool_mesh(&s.hand.tool));
        self.shell.set_home(preview_camera(s.body.solver().mesh()));
        self.panel.draft = s.params;
        self.session = s;
        Ok(())
    }

    /// Open the exercise at `path` and its scene, the mouse holding the blade.
    fn open_exercise(&mut self, path: &Path) -> Result<String> {
        let mode = LiveExercise::open(path)?;
        self.load_scene(mode.scene_path())?;
        let dt = self.session.body.solver().params().frame_dt as f64;
        self.session.hand.take_mouse(0, dt);
        let name = mode.exercise.exercise.name.clone();
        self.exercise = Some(mode);
        Ok(format!(
            "exercise {name}: cut along the violet line; Start attempt when ready"
        ))
    }

    /// Start an attempt at the open exercise from its scene as loaded.
    fn start_attempt(&mut self, reference: bool) -> Result<String> {
        let Some(mode) = &mut self.exercise else {
            bail!("no exercise is open");
        };
        let dev = &self.shell.gpu.dev;
        let stroke = reference.then(|| mode.reference()).transpose()?;
        self.session.reload(dev)?;
        let session = &mut self.session;
        let dt = session.body.solver().params().frame_dt as f64;
        match stroke {
            Some(s) => session.hand.play(s),
            None => session.hand.take_mouse(0, dt),
        }
        let pictures = Screenshots::new(
            Some(dev),
            session.body.solver(),
            &session.skin,
            ATTEMPT_PICTURE,
            Default::default(),
        )
        .map(|s| {
            s.with_tool(&session.hand.tool)
                .with_decal(mode.decal.clone())
                .with_shared_device()
        })
        .map_err(|e| format!("no offscreen renderer ({e:#})"));
        mode.start(&mut session.hand, &mut session.body, pictures)?;
        self.panel.draft = session.params;
        self.panel.playing = true;
        Ok(if reference {
            "attempt started: the reference stroke cuts; Finish attempt to score it".into()
        } else {
            "attempt started: cut along the violet line, then Finish attempt".into()
        })
    }

    /// Score and save the attempt under way, and show its card.
    fn finish_attempt(&mut self) -> Result<String> {
        let Some(mode) = &mut self.exercise else {
            bail!("no exercise is open");
        };
        let done = mode.finish(
            &mut self.session.hand,
            &self.session.body,
            Path::new(ATTEMPTS_DIR),
            Path::new(HISTORY_FILE),
        )?;
        let card = egui::ColorImage::from_rgba_unmultiplied(
            [done.card.width as usize, done.card.height as usize],
            &done.card.pixels,
        );
        self.panel.result_card = Some(self.shell.egui.load_texture(
            "result card",
            card,
            egui::TextureOptions::LINEAR,
        ));
        self.panel.show_result = true;
        let r = &done.attempt.result;
        Ok(format!(
            "{} score {:.0} / 100: saved {} (report.html); replay: incise exercise {} --stroke {}",
            if r.verdict.passed { "PASS" } else { "FAIL" },
            r.verdict.score,
            done.dir.display(),
            mode.exercise.path.display(),
            done.stroke.display()
        ))
    }

    fn act(&mut self, action: Action) -> Result<()> {
        let restarts = matches!(
            action,
            Action::Load(_)
                | Action::Reset
                | Action::Apply(..)
                | Action::StartRecording
                | Action::OpenExercise(_)
                | Action::StartAttempt { .. }
        );
        if restarts {
            let hand = &mut self.session.hand;
            if self.exercise.as_mut().is_some_and(|e| e.abort(hand)) {
                self.panel.message = "attempt abandoned: the scene changed under it".into();
            } else if !matches!(action, Action::StartRecording) && hand.abort_recording() {
                self.panel.message = "recording dropped: the scene changed under it".into();
            }
        }
        let dev = &self.shell.gpu.dev;
        let result = match action {
            Action::Load(path) => self.load_scene(&path).map(|()| {
                self.exercise = None;
                "loaded".to_string()
            }),
            Action::OpenExercise(path) => self.open_exercise(&path),
            Action::StartAttempt { reference } => self.start_attempt(reference),
            Action::FinishAttempt => self.finish_attempt(),
            Action::Step => self.step().map(|_| String::new()).map_err(|e| anyhow!(e)),
            Action::Reset => self.session.reset(dev).map(|()| "reset".into()),
            Action::Apply(params, device) => self
                .session
                .apply(params, device, dev)
                .map(|()| "settings applied".into()),
            Action::ResetView => {
                self.shell.camera = self.shell.home;
                Ok(String::new())
            }
            Action::Screenshot => {
                self.capture_next = true;
                Ok(String::new())
            }
            Action::SaveVtu => self.save_vtu(),
            Action::SetDepth(d) => {
                self.session.hand.input.set_depth(d);
                Ok(String::new())
            }
            Action::PlayStroke(on) => {
                let s = self.session.body.solver();
                let (frame, dt) = (s.frame(), s.params().frame_dt as f64);
                if on {
                    self.session.hand.play_stroke = self.session.hand.has_stroke();
                } else {
                    self.session.hand.take_mouse(frame, dt);
                }
                Ok(String::new())
            }
            Action::StartRecording => self.session.start_recording(dev).map(|()| {
                self.panel.draft = self.session.params;
                "recording from frame 0 (scene reloaded)".into()
            }),
            Action::StopRecording(path) => self.session.hand.stop_recording(&path).map(|r| {
                format!(
                    "saved {} poses to {}; replay: incise run {} --stroke {} --frames {}",
                    r.poses,
                    path.display(),
                    self.session.path.display(),
                    path.display(),
                    r.frames
                )
            }),
        };
        match result {
            Ok(msg) if !msg.is_empty() => self.panel.message = msg,
            Ok(_) => {}
            Err(e) => {
                self.panel.message = format!("{e:#}");
                self.panel.draft = self.session.params;
                self.panel.device = self.session.device;
            }
        }
        Ok(())
    }

    fn save_vtu(&self) -> Result<String> {
        let dir = PathBuf::from("out/preview");
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let solver = self.session.body.solver();
        let path = dir.join(format!("snap_{:05}.vtu", solver.frame()));
        crate::sim_body::xpbd::write_solver_vtu(solver, &path)?;
        Ok(format!("saved {}", path.display()))
    }
}
