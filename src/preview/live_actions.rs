//! What the preview does for the panel's buttons, for a body of any method: load a scene,
//! reset, apply the method's settings, play the scene's script, record a stroke, save a
//! `.vtu`, and an exercise's attempts (started from the scene as loaded, scored and saved
//! as `incise exercise` scores them).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};

use super::live::{Live, hand_for, open_body};
use super::options::{ATTEMPTS_DIR, HISTORY_FILE, PreviewExercise};
use super::panel::Action;
use crate::exercise::live::attempt_pictures;

impl Live {
    /// Do what the panel asked; a failure is shown in the panel.
    pub(super) fn act(&mut self, action: Action) -> Result<()> {
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
            if self
                .exercise
                .as_mut()
                .is_some_and(|e| e.abort(&mut self.hand))
            {
                self.panel.message = "attempt abandoned: the scene changed under it".into();
            } else if !matches!(action, Action::StartRecording) && self.hand.abort_recording() {
                self.panel.message = "recording dropped: the scene changed under it".into();
            }
        }
        let result = match action {
            Action::Load(path) => self.load_scene(&path).map(|()| {
                self.exercise = None;
                "loaded".to_string()
            }),
            Action::OpenExercise(path) => self.open_exercise(&path),
            Action::StartAttempt { reference } => self.start_attempt(reference),
            Action::FinishAttempt => self.finish_attempt(),
            Action::Step => self.step().map(|_| String::new()).map_err(|e| anyhow!(e)),
            Action::Reset => self.reset().map(|()| "reset".into()),
            Action::Apply(settings, device) => self.apply(settings, device),
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
                self.hand.input.set_depth(d);
                Ok(String::new())
            }
            Action::PlayStroke(on) => {
                match on {
                    true => self.hand.give_back(&self.body),
                    false => self.hand.take_mouse(&self.body),
                }
                Ok(String::new())
            }
            Action::StartRecording => self.start_recording(),
            Action::StopRecording(path) => self.stop_recording(&path),
        };
        match result {
            Ok(msg) if !msg.is_empty() => self.panel.message = msg,
            Ok(_) => {}
            Err(e) => {
                self.panel.message = format!("{e:#}");
                self.panel.draft = self.body.body.tunables();
                self.panel.device = self.device;
            }
        }
        Ok(())
    }

    /// Open the scene at `path` in place of the current one.
    fn load_scene(&mut self, path: &Path) -> Result<()> {
        let (body, drawing) = open_body(path, self.device, &self.shell.gpu)?;
        let home = super::camera_input::preview_camera(drawing.mesh_and_skin().0);
        self.hand = hand_for(&body, &drawing, home.yaw)?;
        self.shell.set_home(home);
        self.scene = path.to_path_buf();
        self.replace_body((body, drawing));
        self.panel.draft = self.body.body.tunables();
        Ok(())
    }

    /// The scene as loaded again, on the same device; the blade keeps its place and mouse
    /// state, the script has it back where the scene has one (the mouse keeps it in an
    /// exercise).
    fn reload(&mut self) -> Result<()> {
        let (body, drawing) = open_body(&self.scene, self.device, &self.shell.gpu)?;
        self.hand.fit(&body);
        if self.exercise.is_some() {
            self.hand.take_mouse(&body);
        }
        self.replace_body((body, drawing));
        Ok(())
    }

    /// Start over from rest with the settings in force.
    fn reset(&mut self) -> Result<()> {
        let settings = self.body.body.tunables();
        self.reload()?;
        if let Some(s) = settings.filter(|s| Some(*s) != self.body.body.tunables()) {
            self.body.body.retune(s, self.device)?;
        }
        Ok(())
    }

    /// Apply changed settings (and device) to the running body: it continues from its
    /// motion, cut and grabs; refused settings leave it as it was.
    fn apply(
        &mut self,
        settings: crate::sim_body::Tunables,
        device: crate::sim_body::DeviceChoice,
    ) -> Result<String> {
        self.body
            .body
            .retune(settings, device)
            .with_context(|| self.scene.display().to_string())?;
        self.device = device;
        self.redraw()?;
        Ok("settings applied".into())
    }

    /// Reload the scene and record the hand's poses from frame 0.
    fn start_recording(&mut self) -> Result<String> {
        self.reload()?;
        self.panel.draft = self.body.body.tunables();
        self.hand.start_recording(&mut self.body)?;
        Ok("recording from frame 0 (scene reloaded)".into())
    }

    /// Stop recording and save the stroke at `path`; how to replay it.
    fn stop_recording(&mut self, path: &Path) -> Result<String> {
        let r = self.hand.stop_recording(path)?;
        Ok(format!(
            "saved {} poses to {}; replay: incise run {} --stroke {} --frames {}",
            r.poses,
            path.display(),
            self.scene.display(),
            path.display(),
            r.frames
        ))
    }

    /// Open the exercise at `path` and its scene, the mouse holding the blade.
    fn open_exercise(&mut self, path: &Path) -> Result<String> {
        let e = PreviewExercise::open(path)?;
        self.load_scene(e.scene_path())?;
        self.hand.take_mouse(&self.body);
        let name = e.exercise.exercise.name.clone();
        self.exercise = Some(e);
        Ok(format!(
            "exercise {name}: cut along the violet line; Start attempt when ready"
        ))
    }

    /// Start an attempt at the open exercise from its scene as loaded: the mouse holds
    /// the blade, or the exercise's reference stroke moves it (`reference`).
    fn start_attempt(&mut self, reference: bool) -> Result<String> {
        let Some(e) = &self.exercise else {
            bail!("no exercise is open");
        };
        let stroke = reference.then(|| e.reference()).transpose()?;
        self.reload()?;
        if let Some(s) = stroke {
            self.hand.play(s);
        }
        let Some(e) = &mut self.exercise else {
            bail!("no exercise is open");
        };
        let pictures = attempt_pictures(&self.body, &e.decal);
        e.start(&mut self.hand, &mut self.body, pictures)?;
        self.panel.draft = self.body.body.tunables();
        self.panel.playing = true;
        Ok(if reference {
            "attempt started: the reference stroke cuts; Finish attempt to score it".into()
        } else {
            "attempt started: cut along the violet line, then Finish attempt".into()
        })
    }

    /// Score and save the attempt under way, and show its card.
    fn finish_attempt(&mut self) -> Result<String> {
        let Some(e) = &mut self.exercise else {
            bail!("no exercise is open");
        };
        let out = (Path::new(ATTEMPTS_DIR), Path::new(HISTORY_FILE));
        let done = e.finish(&mut self.hand, &self.body, out.0, out.1)?;
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
            e.exercise.path.display(),
            done.stroke.display()
        ))
    }

    /// The body as a `.vtu` in `out/preview/` (for ParaView).
    fn save_vtu(&self) -> Result<String> {
        let path: PathBuf = self.snapshot_path("out/preview", "vtu");
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        self.body.body.write_vtu(&path)?;
        Ok(format!("saved {}", path.display()))
    }
}
