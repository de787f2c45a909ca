//! The one frame loop of `incise run`, for a body of any method: each frame it checks
//! for Ctrl-C, injects the faults a test asked for, steps the body (a lost GPU hands the
//! body to the CPU), records the frame, the tool's pose, snapshots, checkpoints and
//! pictures.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use incise_scalpel::{HapticCurve, StrokeRecorder};
use incise_sim::io::write_pvd;

use super::ending::RunEnd;
use super::options::{CHECKPOINT_FRAMES, RunOptions};
use crate::pictures::run_pictures::RunPictures;
use crate::progress::Progress;
use crate::report::{FrameData, FrameRecord, Report};
use crate::sim_body::{Fault, SimBody, StepError, ToolInput};

/// A body being run, with everything the run writes.
pub struct FrameLoop<'o> {
    opts: &'o RunOptions,
    body: Box<dyn SimBody>,
    report: Report,
    pvd: Vec<(f64, String)>,
    shots: Option<RunPictures>,
    recorder: Option<StrokeRecorder>,
    progress: Option<Progress>,
    haptic: HapticCurve,
}

/// What a finished loop hands back: the body, its report so far and why it stopped early.
pub type Looped = (Box<dyn SimBody>, Report, Option<RunEnd>);

impl<'o> FrameLoop<'o> {
    /// Prepare to run `body` for `frames` frames as `opts` asks: the output folder, the
    /// stroke recorder, the screenshot renderer, the progress bar.
    pub fn new(
        body: Box<dyn SimBody>,
        mut report: Report,
        opts: &'o RunOptions,
        frames: u64,
    ) -> Result<Self> {
        std::fs::create_dir_all(&opts.out)
            .with_context(|| format!("creating {}", opts.out.display()))?;
        report.frames.reserve(frames as usize);
        let recorder = match (&opts.record_stroke, body.tool_pose()) {
            (None, _) => None,
            (Some(_), None) => bail!("--record-stroke: {} has no tool", opts.scene.display()),
            (Some(_), Some(pose)) => {
                let mut r = StrokeRecorder::new();
                r.push(0.0, pose)?;
                Some(r)
            }
        };
        let shots = match opts.screenshot_every {
            0 => None,
            _ => Some(RunPictures::for_body(
                body.as_ref(),
                opts.screenshot_size,
                opts.screenshot_decal.as_ref(),
            )?),
        };
        Ok(FrameLoop {
            opts,
            body,
            report,
            pvd: Vec::new(),
            shots,
            recorder,
            progress: (!opts.quiet).then(|| Progress::new(frames, 60)),
            haptic: HapticCurve::default(),
        })
    }

    /// Step `frames` frames (stopping early on a failure or Ctrl-C), then write the
    /// collection of snapshots.
    pub fn run(mut self, frames: u64) -> Result<Looped> {
        self.snapshot(0)?;
        self.screenshot(0)?;
        let mut stopped = None;
        for f in 0..frames {
            if crate::interrupt::requested() {
                stopped = Some(RunEnd::Interrupted { frames: f });
                break;
            }
            self.inject_faults(f)?;
            let t0 = Instant::now();
            let mut stepped = self.body.step(&ToolInput::Script);
            if let Err(StepError::DeviceLost(msg)) = &stepped {
                self.warn(format!(
                    "frame {f}: the GPU failed ({msg}); continuing on the CPU from the last completed frame"
                ));
                self.body = self.body.into_cpu();
                self.report.device = format!("{} (after a GPU failure)", self.body.device());
                stepped = self.body.step(&ToolInput::Script);
            }
            match stepped {
                Ok(stats) => self.record(f, stats, t0.elapsed().as_secs_f64() * 1e3),
                Err(e) => {
                    stopped = Some(RunEnd::Failed(e.to_string()));
                    break;
                }
            }
            self.record_stroke(f + 1)?;
            self.snapshot(f + 1)?;
            self.checkpoint(f + 1)?;
            self.screenshot(f + 1)?;
        }
        self.close()?;
        Ok((self.body, self.report, stopped))
    }

    /// Inject the faults the options ask for before frame `f`.
    fn inject_faults(&mut self, f: u64) -> Result<()> {
        if self.opts.inject_gpu_loss_at == Some(f) {
            self.body.inject(Fault::DeviceLoss)?;
        }
        if self.opts.inject_nan_at == Some(f) {
            self.body.inject(Fault::Nan)?;
        }
        Ok(())
    }

    /// Print and keep a warning.
    fn warn(&mut self, warning: String) {
        if !self.opts.quiet {
            eprintln!("warning: {warning}");
        }
        self.report.warnings.push(warning);
    }

    /// Add frame `f`'s record (and the progress line).
    fn record(&mut self, f: u64, stats: FrameData, wall_ms: f64) {
        if let Some(p) = &self.progress {
            p.frame(f, || self.body.progress_line(&stats));
        }
        let haptic_amplitude = self
            .body
            .tool_force()
            .map(|force| self.haptic.amplitude(force.length()));
        self.report.frames.push(FrameRecord {
            haptic_amplitude,
            stats,
            wall_ms,
            gpu_ms: self.body.gpu_frame_ms(),
        });
    }

    /// Record the tool's pose at the end of frame `frame` (t = frame × dt).
    fn record_stroke(&mut self, frame: u64) -> Result<()> {
        let (Some(r), Some(pose)) = (&mut self.recorder, self.body.tool_pose()) else {
            return Ok(());
        };
        Ok(r.push(frame as f64 * self.body.frame_dt(), pose)?)
    }

    /// Write `snap_NNNNN.vtu` when `frame` is due and list it for the collection.
    fn snapshot(&mut self, frame: u64) -> Result<()> {
        let every = self.opts.vtu_every;
        if every == 0 || frame % every != 0 || !self.body.holds_state() {
            return Ok(());
        }
        let name = format!("snap_{frame:05}.vtu");
        self.body.write_vtu(&self.opts.out.join(&name))?;
        self.pvd.push((self.body.time(), name));
        Ok(())
    }

    /// Every [`CHECKPOINT_FRAMES`] frames: write report.json and the recorded stroke so
    /// far (status "running"; both atomically), so a run that is killed keeps them.
    fn checkpoint(&mut self, frame: u64) -> Result<()> {
        if frame % CHECKPOINT_FRAMES != 0 {
            return Ok(());
        }
        self.report.write(&self.report_path())?;
        self.save_stroke()
    }

    /// Write the recorded stroke so far, when recording.
    fn save_stroke(&self) -> Result<()> {
        if let (Some(r), Some(path)) = (&self.recorder, &self.opts.record_stroke) {
            r.clone().finish()?.save(path)?;
        }
        Ok(())
    }

    /// Write `frame_NNNNN.png` when `frame` is due.
    fn screenshot(&mut self, frame: u64) -> Result<()> {
        let Some(shots) = self
            .shots
            .as_mut()
            .filter(|_| frame % self.opts.screenshot_every == 0)
        else {
            return Ok(());
        };
        let path = self.opts.out.join(format!("frame_{frame:05}.png"));
        shots.save(self.body.as_ref(), &path)
    }

    /// After the last frame: the progress bar ended, the collection and the stroke written.
    fn close(&mut self) -> Result<()> {
        if let Some(p) = &self.progress {
            p.finish();
        }
        if !self.pvd.is_empty() {
            write_pvd(&self.opts.out.join("run.pvd"), &self.pvd)?;
            self.report.snapshots = self.pvd.iter().map(|(_, f)| f.clone()).collect();
        }
        self.save_stroke()
    }

    /// Where report.json goes.
    fn report_path(&self) -> PathBuf {
        self.opts.out.join("report.json")
    }
}
