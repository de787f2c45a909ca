//! The egui side panel, for a body of any method: scene picker, play/pause/step/reset,
//! the method's figures, its live settings where it has them (the XPBD material and
//! solver, device), overlays with the heat map's legend, the frame-time graph, the scalpel
//! (depth, force, haptic amplitude, stroke recording), the exercise (its task, attempts,
//! the result card in a "Result" window), and buttons for screenshots and `.vtu`
//! snapshots. It only reports what the user asked for.

use std::path::PathBuf;

use egui::{Color32, Pos2, Rect, Stroke, Vec2};
use incise_sim::contact::CutZone;
use incise_xr::Overlays;
use incise_xr::colour_map::turbo;

use super::frame_times::FrameTimes;
use crate::sim_body::{DeviceChoice, Quantity, Tunables};

/// What the user asked for this frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Open another scene.
    Load(PathBuf),
    /// Advance one frame (while paused).
    Step,
    /// Start the scene over.
    Reset,
    /// Apply changed settings or device to the running body.
    Apply(Tunables, DeviceChoice),
    /// Put the camera back to its start.
    ResetView,
    /// Save a screenshot of the window.
    Screenshot,
    /// Save the body as a `.vtu`.
    SaveVtu,
    /// Set the scalpel's cut depth, m.
    SetDepth(f32),
    /// Let the scene's script move the tool (true) or the mouse (false).
    PlayStroke(bool),
    /// Reload the scene and record the scalpel's poses from frame 0.
    StartRecording,
    /// Stop recording and save the stroke to this file.
    StopRecording(PathBuf),
    /// Open this exercise (and its scene).
    OpenExercise(PathBuf),
    /// Start an attempt at the open exercise from the scene as loaded; `reference`: the
    /// exercise's reference stroke moves the blade instead of the mouse.
    StartAttempt {
        /// Watch the reference stroke instead of cutting.
        reference: bool,
    },
    /// Score and save the attempt under way.
    FinishAttempt,
}

/// Panel state that persists between frames.
pub struct Panel {
    /// Scene files offered.
    pub scenes: Vec<PathBuf>,
    /// Whether the simulation runs.
    pub playing: bool,
    /// Settings as edited (`None`: the body's method has none to change).
    pub draft: Option<Tunables>,
    /// Device as chosen.
    pub device: DeviceChoice,
    /// Overlays shown.
    pub overlays: Overlays,
    /// Status line (last save, last error).
    pub message: String,
    /// Where a recorded stroke is saved.
    pub stroke_file: String,
    /// Exercise files offered.
    pub exercises: Vec<PathBuf>,
    /// The last attempt's result card.
    pub result_card: Option<egui::TextureHandle>,
    /// Whether the "Result" window is open.
    pub show_result: bool,
}

/// What the panel shows of the open exercise.
pub struct ExerciseInfo {
    /// Exercise name.
    pub name: String,
    /// Its file.
    pub file: PathBuf,
    /// The task in words.
    pub description: String,
    /// Target depth and allowed depth error, m.
    pub depth: (f32, f32),
    /// Half-width of the band around the plan, m.
    pub lateral: f32,
    /// Time limit, s.
    pub time_limit: f32,
    /// Simulated time of the attempt under way, s.
    pub running: Option<f64>,
}

/// What the panel shows of the scalpel.
pub struct ScalpelInfo {
    /// Tool name.
    pub name: String,
    /// Whether the left button holds the blade in the tissue.
    pub cutting: bool,
    /// Whether the blade waits parked above the tissue.
    pub parked: bool,
    /// Cut depth and its limit, m.
    pub depth: (f32, f32),
    /// Tissue force on the tool in the last frame, N.
    pub force: f32,
    /// Haptic amplitude for it, 0..1.
    pub amplitude: f32,
    /// Poses recorded so far, when recording.
    pub recording: Option<usize>,
    /// Whether the scene has a script that moves its tool, and whether something other
    /// than the mouse moves it now (the script, or a played stroke).
    pub stroke: (bool, bool),
}

impl ScalpelInfo {
    /// The state of `hand` on a body whose script can move the tool (`script`).
    pub fn of(hand: &super::hand::PreviewHand, script: bool) -> Self {
        ScalpelInfo {
            name: hand.tool.name().to_string(),
            cutting: hand.input.cutting(),
            parked: hand.input.is_parked(),
            depth: (hand.input.depth(), hand.input.geometry().max_depth),
            force: hand.force,
            amplitude: hand.amplitude,
            recording: hand.recording(),
            stroke: (script, hand.holder() != super::hand::Holder::Mouse),
        }
    }
}

/// What the panel shows about the running scene.
pub struct PanelInfo<'a> {
    /// Scene file in use.
    pub scene: &'a std::path::Path,
    /// The body's method.
    pub method: &'a str,
    /// Simulation frame.
    pub frame: u64,
    /// The method's figures of the last frame (released tets and stress, cut counts…).
    pub status: String,
    /// A mass-spring body's localisation in the last frame.
    pub live_lines: Vec<String>,
    /// What the heat map shows.
    pub quantity: Option<Quantity>,
    /// Top of the heat-map scale, in the quantity's unit.
    pub heat_max: f32,
    /// "cpu" or the GPU adapter.
    pub device: String,
    /// Recent timings.
    pub times: &'a FrameTimes,
    /// The scalpel.
    pub scalpel: ScalpelInfo,
    /// The open exercise, if any.
    pub exercise: Option<ExerciseInfo>,
}

impl Panel {
    /// Draw the panel into `ui`; returns the actions asked for and the panel's width in
    /// points.
    pub fn ui(&mut self, ui: &mut egui::Ui, info: &PanelInfo<'_>) -> (Vec<Action>, f32) {
        let mut actions = Vec::new();
        let shown = egui::Panel::left("controls")
            .default_size(270.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.scene_section(ui, info, &mut actions);
                    ui.separator();
                    self.exercise_section(ui, info.exercise.as_ref(), &mut actions);
                    ui.separator();
                    self.settings_section(ui, &mut actions);
                    let attempt = info.exercise.as_ref().is_some_and(|e| e.running.is_some());
                    self.scalpel_section(ui, &info.scalpel, attempt, &mut actions);
                    ui.separator();
                    self.overlay_section(ui, info);
                    ui.separator();
                    timing_section(ui, info);
                    if !self.message.is_empty() {
                        ui.separator();
                        ui.label(&self.message);
                    }
                    ui.separator();
                    ui.small("Left-drag: cut · right-drag: orbit · middle/shift+right-drag: pan · wheel: zoom (depth while cutting or with Ctrl) · R: reset view · F: fullscreen · Space: play");
                });
            });
        self.result_window(ui.ctx());
        (actions, shown.response.rect.width())
    }

    fn exercise_section(
        &mut self,
        ui: &mut egui::Ui,
        ex: Option<&ExerciseInfo>,
        actions: &mut Vec<Action>,
    ) {
        ui.heading("Exercise");
        let current = ex.map_or("none".to_string(), |e| file_name(&e.file));
        egui::ComboBox::from_id_salt("exercise")
            .selected_text(current.clone())
            .show_ui(ui, |ui| {
                for f in &self.exercises {
                    let name = file_name(f);
                    if ui.selectable_label(name == current, name).clicked() {
                        actions.push(Action::OpenExercise(f.clone()));
                    }
                }
            });
        let Some(ex) = ex else {
            ui.small("Pick an exercise: a planned incision to cut, scored.");
            return;
        };
        ui.label(egui::RichText::new(&ex.name).strong());
        ui.label(&ex.description);
        let mm = |v: f32| v * 1e3;
        ui.small(format!(
            "depth {:.1} mm ± {:.1} mm · within {:.1} mm of the violet line · {:.0} s",
            mm(ex.depth.0),
            mm(ex.depth.1),
            mm(ex.lateral),
            ex.time_limit
        ));
        match ex.running {
            None => {
                ui.horizontal(|ui| {
                    if ui.button("Start attempt").clicked() {
                        actions.push(Action::StartAttempt { reference: false });
                    }
                    if ui.button("Watch the reference").clicked() {
                        actions.push(Action::StartAttempt { reference: true });
                    }
                });
            }
            Some(t) => {
                ui.horizontal(|ui| {
                    if ui.button("Finish attempt").clicked() {
                        actions.push(Action::FinishAttempt);
                    }
                    ui.label(format!("attempt: {t:.1} s"));
                });
            }
        }
        if self.result_card.is_some() && !self.show_result && ui.button("Show result").clicked() {
            self.show_result = true;
        }
    }

    /// The last result card in its own window, while open.
    fn result_window(&mut self, ctx: &egui::Context) {
        let Some(card) = &self.result_card else {
            return;
        };
        let size = card.size_vec2() * 0.75;
        egui::Window::new("Result")
            .open(&mut self.show_result)
            .default_pos(egui::pos2(300.0, 40.0))
            .resizable(false)
            .show(ctx, |ui| {
                ui.image(egui::load::SizedTexture::new(card.id(), size));
            });
    }

    fn scene_section(
        &mut self,
        ui: &mut egui::Ui,
        info: &PanelInfo<'_>,
        actions: &mut Vec<Action>,
    ) {
        ui.heading("Scene");
        let current = file_name(info.scene);
        egui::ComboBox::from_label("")
            .selected_text(current.clone())
            .show_ui(ui, |ui| {
                for s in &self.scenes {
                    let name = file_name(s);
                    if ui.selectable_label(name == current, name).clicked() {
                        actions.push(Action::Load(s.clone()));
                    }
                }
            });
        ui.horizontal(|ui| {
            let label = if self.playing { "Pause" } else { "Play" };
            if ui.button(label).clicked() {
                self.playing = !self.playing;
            }
            if ui
                .add_enabled(!self.playing, egui::Button::new("Step"))
                .clicked()
            {
                actions.push(Action::Step);
            }
            if ui.button("Reset").clicked() {
                actions.push(Action::Reset);
            }
        });
        ui.horizontal(|ui| {
            if ui.button("Screenshot").clicked() {
                actions.push(Action::Screenshot);
            }
            if ui.button("Save .vtu").clicked() {
                actions.push(Action::SaveVtu);
            }
            if ui.button("Reset view").clicked() {
                actions.push(Action::ResetView);
            }
        });
        ui.label(format!("{} body · frame {}", info.method, info.frame));
        if !info.status.is_empty() {
            ui.label(&info.status);
        }
        for line in &info.live_lines {
            ui.small(line);
        }
    }

    /// The method's live settings, where it has them.
    fn settings_section(&mut self, ui: &mut egui::Ui, actions: &mut Vec<Action>) {
        let Some(d) = &mut self.draft else {
            return;
        };
        ui.heading("Material and solver");
        let slider = |ui: &mut egui::Ui, s: egui::Slider<'_>| {
            let r = ui.add(s);
            r.drag_stopped() || (r.changed() && !r.dragged())
        };
        let mut done = false;
        done |= slider(
            ui,
            egui::Slider::new(&mut d.youngs_modulus, 1e3..=1e6)
                .logarithmic(true)
                .text("E (Pa)"),
        );
        done |= slider(
            ui,
            egui::Slider::new(&mut d.poisson_ratio, d.poisson_range.0..=d.poisson_range.1)
                .text("ν"),
        );
        done |= slider(
            ui,
            egui::Slider::new(&mut d.damping, 0.0..=50.0).text("damping (1/s)"),
        );
        ui.horizontal(|ui| {
            ui.label("scheme");
            for (implicit, name) in [(false, "XPBD"), (true, "implicit (Newton)")] {
                done |= ui
                    .selectable_value(&mut d.implicit, implicit, name)
                    .clicked();
            }
        });
        if d.implicit {
            done |= slider(
                ui,
                egui::Slider::new(&mut d.newton.iterations, 1..=20).text("Newton iterations"),
            );
            done |= slider(
                ui,
                egui::Slider::new(&mut d.newton.cg_iterations, 5..=400).text("CG products a solve"),
            );
        } else {
            done |= slider(
                ui,
                egui::Slider::new(&mut d.substeps, 1..=400).text("substeps"),
            );
        }
        let mut cutting = d.cut_threshold.is_some();
        let toggled = ui.checkbox(&mut cutting, "cutting").changed();
        done |= toggled;
        if cutting {
            let mut t = d.cut_threshold.unwrap_or(1e5);
            done |= slider(
                ui,
                egui::Slider::new(&mut t, 1e2..=1e7)
                    .logarithmic(true)
                    .text("cut σvM (Pa)"),
            );
            d.cut_threshold = Some(t);
            let mut edge = d.cut_zone != CutZone::Anywhere;
            let r = ui
                .checkbox(&mut edge, "only along the blade's edge")
                .on_hover_text(
                    "off: tets release wherever the stress passes the threshold (tearing)",
                );
            if r.changed() {
                d.cut_zone = if edge { d.edge_zone } else { CutZone::Anywhere };
                done = true;
            }
        } else {
            d.cut_threshold = None;
        }
        ui.horizontal(|ui| {
            ui.label("device");
            for (choice, name) in [(DeviceChoice::Cpu, "cpu"), (DeviceChoice::Gpu, "gpu")] {
                if ui
                    .selectable_value(&mut self.device, choice, name)
                    .clicked()
                {
                    done = true;
                }
            }
        });
        if done {
            actions.push(Action::Apply(*d, self.device));
        }
        ui.separator();
    }

    /// `attempt`: an exercise attempt is under way (it owns the recording).
    fn scalpel_section(
        &mut self,
        ui: &mut egui::Ui,
        s: &ScalpelInfo,
        attempt: bool,
        actions: &mut Vec<Action>,
    ) {
        ui.heading("Scalpel");
        let state = match (s.stroke.1, s.cutting, s.parked) {
            (true, ..) => "the scene's script or a stroke moves it",
            (_, true, _) => "cutting",
            (_, _, true) => "parked: move the cursor over the tissue",
            _ => "lifted",
        };
        ui.label(format!("{} · {state}", s.name));
        let (depth, max) = s.depth;
        let mut mm = depth * 1e3;
        let r = ui.add(egui::Slider::new(&mut mm, 0.0..=max * 1e3).text("depth (mm)"));
        if r.changed() {
            actions.push(Action::SetDepth(mm * 1e-3));
        }
        if s.stroke.0 {
            let mut play = s.stroke.1;
            if ui
                .checkbox(&mut play, "the scene's script moves it")
                .changed()
            {
                actions.push(Action::PlayStroke(play));
            }
        }
        ui.label(format!("tool force {:.3} N", s.force));
        ui.add(
            egui::ProgressBar::new(s.amplitude.clamp(0.0, 1.0))
                .text(format!("haptic {:.2}", s.amplitude)),
        );
        ui.horizontal(|ui| {
            ui.label("stroke file");
            ui.text_edit_singleline(&mut self.stroke_file);
        });
        match s.recording {
            // The attempt records the stroke and saves it when finished.
            Some(n) if attempt => {
                ui.label(format!("recording the attempt: {n} poses"));
            }
            None => {
                if ui.button("Record stroke").clicked() {
                    actions.push(Action::StartRecording);
                }
            }
            Some(n) => {
                ui.horizontal(|ui| {
                    if ui.button("Stop and save").clicked() {
                        actions.push(Action::StopRecording(PathBuf::from(&self.stroke_file)));
                    }
                    ui.label(format!("recording: {n} poses"));
                });
            }
        }
    }

    fn overlay_section(&mut self, ui: &mut egui::Ui, info: &PanelInfo<'_>) {
        ui.heading("Overlays");
        let o = &mut self.overlays;
        let q = info.quantity.map_or(("heat map", ""), |q| (q.name, q.unit));
        ui.checkbox(&mut o.stress, format!("heat map: {}", q.0));
        if o.stress {
            legend(ui, info.heat_max, q.1);
        }
        ui.checkbox(&mut o.wireframe, "tet wireframe");
        ui.checkbox(&mut o.tool_spheres, "tool contact spheres");
        ui.checkbox(&mut o.pinned, "pinned nodes");
    }
}

fn file_name(p: &std::path::Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The heat map's colour bar from 0 to `max` (in `unit`).
fn legend(ui: &mut egui::Ui, max: f32, unit: &str) {
    let (rect, _) = ui.allocate_exact_size(
        Vec2::new(ui.available_width().min(240.0), 14.0),
        egui::Sense::hover(),
    );
    let n = 48;
    for i in 0..n {
        let t = i as f32 / (n - 1) as f32;
        let c = turbo(t).map(|v| (v * 255.0) as u8);
        let x0 = rect.left() + rect.width() * i as f32 / n as f32;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / n as f32;
        ui.painter().rect_filled(
            Rect::from_min_max(
                Pos2::new(x0, rect.top()),
                Pos2::new(x1 + 0.5, rect.bottom()),
            ),
            0.0,
            Color32::from_rgb(c[0], c[1], c[2]),
        );
    }
    ui.horizontal(|ui| {
        ui.small(format!("0 {unit}"));
        ui.add_space(ui.available_width() - 90.0);
        ui.small(format!("{max:.3e} {unit}"));
    });
}

/// Picks one timing out of a frame.
type Series = fn(&super::frame_times::FrameTime) -> f64;

/// Frame-time graph: sim (orange), render (blue) and whole frame (grey), ms.
fn timing_section(ui: &mut egui::Ui, info: &PanelInfo<'_>) {
    ui.heading("Frame time");
    let m = info.times.recent_mean();
    ui.label(format!(
        "sim {:.1} ms · render {:.1} ms · {:.0} fps",
        m.sim_ms,
        m.render_ms,
        info.times.fps()
    ));
    ui.small(&info.device);
    let (rect, _) = ui.allocate_exact_size(
        Vec2::new(ui.available_width().min(240.0), 70.0),
        egui::Sense::hover(),
    );
    let p = ui.painter();
    p.rect_filled(rect, 2.0, Color32::from_gray(24));
    let frames: Vec<_> = info.times.frames().copied().collect();
    let top = frames
        .iter()
        .map(|f| f.frame_ms.max(f.sim_ms).max(f.render_ms))
        .fold(16.7, f64::max);
    let n = frames.len().max(2);
    let point = |i: usize, v: f64| {
        Pos2::new(
            rect.left() + rect.width() * i as f32 / (n - 1) as f32,
            rect.bottom() - rect.height() * (v / top) as f32,
        )
    };
    let series: [(Series, Color32); 3] = [
        (|f| f.frame_ms, Color32::from_gray(150)),
        (|f| f.sim_ms, Color32::from_rgb(240, 150, 40)),
        (|f| f.render_ms, Color32::from_rgb(80, 160, 250)),
    ];
    for (get, colour) in series {
        let pts: Vec<Pos2> = frames
            .iter()
            .enumerate()
            .map(|(i, f)| point(i, get(f)))
            .collect();
        p.add(egui::Shape::line(pts, Stroke::new(1.0, colour)));
    }
    p.text(
        rect.left_top() + Vec2::new(3.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{top:.0} ms"),
        egui::FontId::proportional(10.0),
        Color32::from_gray(180),
    );
}
