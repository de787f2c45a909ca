//! An exercise attempted on a live body, in the preview or the headset: its plan drawn on
//! the tissue, and attempts — started from the scene as loaded with the scalpel's poses
//! recorded (by a [`StrokeSource`]: the preview's mouse blade, the right controller) and
//! every frame's statistics kept, finished by scoring the live body with the same
//! [`score_attempt`] as `incise exercise` and saving result.json, report.html, the stroke
//! and the result card. No window needed: tests drive it with a source and any method's
//! [`RecordedBody`] (an XPBD body is scored on its released tets, a Nakao body on its cut
//! surface).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use incise_xr::RgbaImage;

use super::{
    Attempt, CutImages, LoadedExercise, ReferenceStyle, Standing, ToolFrame, load_exercise,
    read_history, reference_stroke, render_card, save_attempt, score_attempt,
};
use crate::pictures::plan_decal::PlanDecal;
use crate::pictures::run_pictures::RunPictures;
use crate::pictures::screenshots::ImageSize;
use crate::sim_body::RestCut;
use crate::sim_body::recorded::RecordedBody;

/// Size of the before/after pictures in a live attempt's report, pixels.
pub const ATTEMPT_PICTURE: ImageSize = ImageSize(960, 540);

/// The offscreen pictures of a live attempt on `body`: an XPBD body's own, with the
/// exercise's plan `decal` drawn on it, else its tet view with the heat map of the
/// method's quantity (an error kept as text: the attempt is then saved without).
pub fn attempt_pictures(body: &RecordedBody, decal: &PlanDecal) -> Result<RunPictures, String> {
    let decal = body.body.solver_parts().map(|_| decal);
    RunPictures::for_body(&*body.body, ATTEMPT_PICTURE, decal).map_err(|e| format!("{e:#}"))
}

/// Where a live attempt's scalpel path is recorded on a body `B`: the preview's hand
/// hand, the XR mode's controller.
pub trait StrokeSource<B: ?Sized> {
    /// Start recording on `body`, which is at frame 0.
    fn start_recording(&mut self, body: &mut B) -> Result<()>;
    /// Whether a recording is running.
    fn is_recording(&self) -> bool;
    /// Stop recording and write the stroke to `path` atomically.
    fn save_recording(&mut self, path: &Path) -> Result<()>;
    /// Drop a running recording without saving it.
    fn abort_recording(&mut self);
}

/// What an attempt needs of the body it is made on.
pub trait AttemptBody {
    /// The offscreen renderer of the report's pictures of this body.
    type Pictures;
    /// Tets of the body's mesh, where they must be the exercise mesh's (XPBD releases
    /// them by index); `None` where a cut remodels the mesh.
    fn scene_tets(&self) -> Option<usize>;
    /// What the body has cut, at rest.
    fn rest_cut(&self) -> Result<RestCut>;
    /// Where the body runs.
    fn device(&self) -> String;
    /// A picture of the body now.
    fn picture(&self, pictures: &mut Self::Pictures) -> Result<RgbaImage>;
    /// Frames stepped since the scene was loaded.
    fn frame(&self) -> u64;
}

impl AttemptBody for RecordedBody {
    type Pictures = RunPictures;
    fn scene_tets(&self) -> Option<usize> {
        let parts = self.body.solver_parts()?;
        Some(parts.body.solver().mesh().tet_count())
    }
    fn rest_cut(&self) -> Result<RestCut> {
        self.body.rest_cut().ok_or_else(|| {
            anyhow!(
                "a {} body leaves no cut to score",
                self.body.method().name()
            )
        })
    }
    fn device(&self) -> String {
        self.body.device()
    }
    fn picture(&self, pictures: &mut RunPictures) -> Result<RgbaImage> {
        pictures.image(&*self.body)
    }
    fn frame(&self) -> u64 {
        self.frames() as u64
    }
}

/// An exercise open on a live body, its report's pictures taken by `P`.
pub struct LiveExercise<P> {
    /// The exercise, its scene and plan.
    pub exercise: LoadedExercise,
    /// The plan as a line on the tissue.
    pub decal: PlanDecal,
    attempt: Option<Running<P>>,
}

/// An attempt under way.
struct Running<P> {
    /// The tool figures of every frame since the start.
    tool: Vec<ToolFrame>,
    /// The renderer for the report's pictures and the picture at the start, or why there
    /// are none.
    pictures: Result<(P, RgbaImage), String>,
}

/// A finished, scored and saved attempt.
pub struct Finished {
    /// The result and where result.json and report.html are.
    pub attempt: Attempt,
    /// The attempt's folder.
    pub dir: PathBuf,
    /// The recorded stroke (replay: `incise exercise EXERCISE --stroke FILE`).
    pub stroke: PathBuf,
    /// Where the attempt stands in the history, when the history could be read back.
    pub standing: Option<Standing>,
    /// The result card (also saved as card.png).
    pub card: RgbaImage,
}

impl<P> LiveExercise<P> {
    /// Load the exercise at `path` and lay its plan on the mesh.
    pub fn open(path: &Path) -> Result<LiveExercise<P>> {
        let exercise = load_exercise(path)?;
        let decal = exercise.plan.decal(&exercise.mesh);
        Ok(LiveExercise {
            exercise,
            decal,
            attempt: None,
        })
    }

    /// The exercise's scene file.
    pub fn scene_path(&self) -> &Path {
        &self.exercise.scene_path
    }

    /// The exercise's reference stroke (what a good attempt looks like).
    pub fn reference(&self) -> Result<incise_scalpel::Stroke> {
        reference_stroke(&self.exercise, ReferenceStyle::default())
    }

    /// Start an attempt on `body`, which must be the exercise's scene as loaded (frame 0):
    /// the scalpel's poses are recorded from now on, and the start is pictured with
    /// `pictures` (the renderer for the report, or why there is none).
    pub fn start<B: AttemptBody<Pictures = P> + ?Sized>(
        &mut self,
        hand: &mut dyn StrokeSource<B>,
        body: &mut B,
        pictures: Result<P, String>,
    ) -> Result<()> {
        if body
            .scene_tets()
            .is_some_and(|n| n != self.exercise.mesh.tet_count())
        {
            bail!(
                "the scene running is not {}'s scene {}",
                self.exercise.exercise.name,
                self.exercise.scene_path.display()
            );
        }
        hand.abort_recording();
        hand.start_recording(body)?;
        let pictures = pictures.and_then(|mut shots| {
            let before = body.picture(&mut shots).map_err(|e| format!("{e:#}"))?;
            Ok((shots, before))
        });
        self.attempt = Some(Running {
            tool: Vec::new(),
            pictures,
        });
        Ok(())
    }

    /// Whether the blade has touched the tissue in the attempt under way.
    pub fn touched(&self) -> bool {
        self.attempt
            .as_ref()
            .is_some_and(|a| a.tool.iter().any(|f| f.contact))
    }

    /// Frames simulated in the attempt under way, if one is.
    pub fn running(&self) -> Option<usize> {
        self.attempt.as_ref().map(|a| a.tool.len())
    }

    /// Keep a simulated frame's tool figures (nothing without an attempt).
    pub fn after_step(&mut self, frame: ToolFrame) {
        if let Some(a) = &mut self.attempt {
            a.tool.push(frame);
        }
    }

    /// Drop the attempt under way (the scene changed under it); whether there was one.
    pub fn abort<B: ?Sized>(&mut self, hand: &mut dyn StrokeSource<B>) -> bool {
        hand.abort_recording();
        self.attempt.take().is_some()
    }

    /// Finish the attempt: score `body` as it is now (what it cut and the frames kept),
    /// and save into a new folder `out_root/<exercise>-<UTC time>/` the recorded
    /// stroke.ron, result.json, report.html (with pictures of the start and now when a
    /// renderer was given), and card.png; the attempt is appended to `history`.
    pub fn finish<B: AttemptBody<Pictures = P> + ?Sized>(
        &mut self,
        hand: &mut dyn StrokeSource<B>,
        body: &B,
        out_root: &Path,
        history: &Path,
    ) -> Result<Finished> {
        let running = self
            .attempt
            .as_ref()
            .ok_or_else(|| anyhow!("no attempt is under way"))?;
        // The frames of the attempt are those whose statistics were kept (the XR mode
        // rebuilds its solver when it changes substeps, which restarts the solver's own
        // frame count).
        let frames = running.tool.len() as u64;
        if frames == 0 {
            bail!("the attempt has not simulated a frame yet");
        }
        if !hand.is_recording() {
            bail!("the attempt's stroke recording was stopped; start the attempt again");
        }
        let Some(running) = self.attempt.take() else {
            bail!("no attempt is under way");
        };
        let name = &self.exercise.exercise.name;
        let dir = new_attempt_dir(out_root, name)?;
        let stroke = dir.join("stroke.ron");
        hand.save_recording(&stroke)?;
        let result = score_attempt(
            &self.exercise,
            &stroke.display().to_string(),
            body.device(),
            &body.rest_cut()?,
            &running.tool,
            frames,
        )?;
        let (before, after) = (dir.join("before.png"), dir.join("after.png"));
        let images = match running.pictures {
            Ok((mut shots, first)) => match body.picture(&mut shots) {
                Ok(last) => {
                    first.save_png(&before)?;
                    last.save_png(&after)?;
                    CutImages::Files(vec![
                        ("Before the attempt", before.as_path()),
                        ("After the attempt", after.as_path()),
                    ])
                }
                Err(e) => CutImages::Missing(format!("{e:#}")),
            },
            Err(why) => CutImages::Missing(why),
        };
        let attempt = save_attempt(&dir, result, &images, history)?;
        let standing = read_history(history)
            .ok()
            .and_then(|h| Standing::in_history(&h, name));
        let card = render_card(&attempt.result, standing)?;
        card.save_png(&dir.join("card.png"))?;
        Ok(Finished {
            attempt,
            dir,
            stroke,
            standing,
            card,
        })
    }
}

/// A new folder `root/<name>-<UTC time, compact>` (`-2`, `-3`, … appended when taken).
fn new_attempt_dir(root: &Path, name: &str) -> Result<PathBuf> {
    let stamp: String = crate::exercise::utc_now()
        .chars()
        .filter(|c| !matches!(c, '-' | ':'))
        .collect();
    std::fs::create_dir_all(root).with_context(|| format!("creating {}", root.display()))?;
    for k in 1..1000 {
        let dir = match k {
            1 => root.join(format!("{name}-{stamp}")),
            k => root.join(format!("{name}-{stamp}-{k}")),
        };
        match std::fs::create_dir(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e).with_context(|| format!("creating {}", dir.display())),
        }
    }
    bail!("{}: no free folder name for {name}-{stamp}", root.display())
}
