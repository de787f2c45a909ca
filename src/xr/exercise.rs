//! An exercise in the headset (issue 10): the plan drawn on the tissue in both eyes, the
//! attempt recorded from the right controller from the scene as loaded, finished with A
//! (scored like `incise exercise`, saved with its stroke, report and card, and the result
//! card hung above the tray); A again starts a new attempt on a fresh scene. An attempt
//! in which the blade touched the tissue is also finished and saved when the session
//! ends, however it ends.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use incise_sim::contact::ToolPose;
use incise_xr::openxr::result_panel::panel_transform;
use incise_xr::openxr::tray::Tray;
use incise_xr::{RenderDevice, Renderer, RgbaImage};
use serde::Serialize;

use crate::exercise::live::attempt_pictures;
use crate::exercise::{LiveExercise, LoadedExercise, PoseRecording, ToolFrame};
use crate::pictures::plan_decal::PlanDecal;
use crate::pictures::run_pictures::RunPictures;
use crate::sim_body::recorded::RecordedBody;

/// What became of one attempt in the session (in `xr_report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct AttemptSummary {
    /// The attempt's folder (result.json, report.html, stroke.ron, card.png).
    pub dir: String,
    /// Overall score, 0..100.
    pub score: f64,
    /// Whether every pass condition held.
    pub passed: bool,
    /// Why it ended: "A pressed" or "session ended".
    pub ended_by: String,
}

/// The exercise state of an XR session on a body of any method (an XPBD body scored on
/// its released tets, a Nakao body on its cut surface).
pub struct XrExercise {
    live: LiveExercise<RunPictures>,
    /// The right controller's path during an attempt, timed by simulated frames since
    /// the attempt's start (so `incise exercise --stroke` replays it on the scene as
    /// loaded).
    stroke: PoseRecording,
    out_root: PathBuf,
    history: PathBuf,
    /// The card on show.
    card: Option<RgbaImage>,
    /// Whether the renderer's panel image must be replaced (by the card, or removed).
    card_changed: bool,
    /// Attempts finished in this session.
    pub attempts: Vec<AttemptSummary>,
}

impl XrExercise {
    /// Open the exercise at `path`; attempts are saved under `out_root` and appended to
    /// `history`.
    pub fn open(path: &Path, out_root: &Path, history: &Path) -> Result<XrExercise> {
        Ok(XrExercise {
            live: LiveExercise::open(path)?,
            stroke: PoseRecording::default(),
            out_root: out_root.to_path_buf(),
            history: history.to_path_buf(),
            card: None,
            card_changed: false,
            attempts: Vec::new(),
        })
    }

    /// The exercise (its scene file is what the session loads).
    pub fn exercise(&self) -> &LoadedExercise {
        &self.live.exercise
    }

    /// The plan on the tissue.
    pub fn decal(&self) -> &PlanDecal {
        &self.live.decal
    }

    /// Start an attempt on `body`, the exercise's scene as loaded; pictures of the report
    /// are taken offscreen.
    pub fn start(&mut self, body: &mut RecordedBody) -> Result<()> {
        self.card_changed |= self.card.take().is_some();
        let pictures = attempt_pictures(body, &self.live.decal);
        self.live.start(&mut self.stroke, body, pictures)
    }

    /// After a simulated frame: keep its tool figures and the scalpel's pose (when the
    /// controller is tracked) with whether the trigger engaged it.
    pub fn after_step(
        &mut self,
        frame: ToolFrame,
        pose: Option<ToolPose>,
        engaged: bool,
        dt: f64,
    ) -> Result<()> {
        self.live.after_step(frame);
        // The attempt's clock: its frames so far (none kept without an attempt).
        let frames = self.live.running().unwrap_or(0);
        if let Some(p) = pose {
            self.stroke.push(frames as f64 * dt, p, engaged)?;
        }
        Ok(())
    }

    /// A pressed. With an attempt in which the blade touched the tissue: finish it (the
    /// card is shown; returns false: keep the scene). Otherwise: returns true, the caller
    /// resets the scene and calls [`XrExercise::start`].
    pub fn on_a(&mut self, xr: &RecordedBody) -> Result<bool> {
        if self.live.touched() {
            self.finish(xr, "A pressed")?;
            Ok(false)
        } else {
            self.live.abort::<RecordedBody>(&mut self.stroke);
            Ok(true)
        }
    }

    /// The session is over: finish an attempt in which the blade touched the tissue.
    pub fn end_session(&mut self, xr: &RecordedBody) -> Result<()> {
        if self.live.touched() {
            self.finish(xr, "session ended")?;
        }
        Ok(())
    }

    /// The solver failed (`why`; its last frame rolled back) and the scene is about to
    /// be reset: an attempt the blade touched is scored and saved as it stood, others are
    /// dropped.
    pub fn on_solver_failure(&mut self, xr: &RecordedBody, why: &str) -> Result<()> {
        if self.live.touched() {
            self.finish(xr, &format!("solver failed: {why}"))
        } else {
            self.live.abort::<RecordedBody>(&mut self.stroke);
            Ok(())
        }
    }

    fn finish(&mut self, xr: &RecordedBody, why: &str) -> Result<()> {
        if self.stroke.is_empty() {
            // The blade touched with no tracked pose recorded (cannot happen while the
            // tool follows the controller); nothing to replay: drop it.
            self.live.abort::<RecordedBody>(&mut self.stroke);
            bail!("the attempt has no recorded scalpel poses");
        }
        let done = self
            .live
            .finish(&mut self.stroke, xr, &self.out_root, &self.history)?;
        eprintln!(
            "xr: {} — {} ({})",
            done.attempt.result.summary(),
            done.dir.display(),
            why
        );
        self.attempts.push(AttemptSummary {
            dir: done.dir.display().to_string(),
            score: done.attempt.result.verdict.score,
            passed: done.attempt.result.verdict.passed,
            ended_by: why.to_string(),
        });
        self.card = Some(done.card);
        self.card_changed = true;
        Ok(())
    }

    /// The renderer the card was uploaded to was replaced: upload it again.
    pub fn renderer_replaced(&mut self) {
        self.card_changed |= self.card.is_some();
    }

    /// The card's placement (sim world) for a head at `head` (stage), uploading the card
    /// to `renderer` the first time; `None` while no card is shown.
    pub fn panel(
        &mut self,
        renderer: &mut Renderer,
        dev: &RenderDevice,
        tray: &Tray,
        head: Vec3,
    ) -> Result<Option<Mat4>> {
        if self.card_changed {
            let image = self
                .card
                .as_ref()
                .map(|c| (c.pixels.as_slice(), c.width, c.height));
            renderer.set_panel_image(&dev.device, &dev.queue, image)?;
            self.card_changed = false;
        }
        let Some(card) = &self.card else {
            return Ok(None);
        };
        let aspect = card.height as f32 / card.width.max(1) as f32;
        Ok(Some(panel_transform(tray, head, aspect)))
    }
}
