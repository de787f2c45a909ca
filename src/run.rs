//! `incise run`: the headless runner. Steps a scene, writes report.json, .vtu snapshots and
//! a .pvd collection; on a solver failure the output written so far is kept and the report
//! says what failed.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use incise_sim::io::{VtuFrame, write_pvd, write_vtu};
use incise_sim::xpbd::SolverError;

use crate::body::{Body, DeviceChoice};
use crate::exercise::PlanDecal;
use crate::progress::Progress;
use crate::report::{FrameData, FrameRecord, MaterialInfo, MeshInfo, Report, ToolInfo};
use crate::scene::{BuiltScene, ToolDriver, build_scene_driven, load_scene};
use crate::screenshots::{ImageSize, Screenshots};

/// Frames between checkpoints of report.json and the recorded stroke (1 s at 60 Hz).
pub const CHECKPOINT_FRAMES: u64 = 60;

/// Options of `incise run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Scene file.
    pub scene: PathBuf,
    /// Frames to run (default: the scene's duration).
    pub frames: Option<u64>,
    /// Output folder.
    pub out: PathBuf,
    /// Write a .vtu every K frames (0 = none).
    pub vtu_every: u64,
    /// Solver threads (default: the scene's, 0 = all cores).
    pub threads: Option<usize>,
    /// Suppress progress output.
    pub quiet: bool,
    /// Where the solver runs.
    pub device: DeviceChoice,
    /// Write an offscreen `frame_NNNNN.png` every K frames (0 = none).
    pub screenshot_every: u64,
    /// Size of those screenshots.
    pub screenshot_size: ImageSize,
    /// Run a mass-spring scene's local loop on its own thread at this rate, Hz (the
    /// haptic-rate option, PHYSICS.md §2.6); `None`: the ordinary frame loop.
    pub haptic_rate: Option<f64>,
    /// Drive the scene's tool with this stroke file instead of the scene's stroke.
    pub stroke: Option<PathBuf>,
    /// Record the tool's pose at every frame to this stroke file (replayable with
    /// `--stroke`, bit for bit).
    pub record_stroke: Option<PathBuf>,
    /// Fault injection for tests: lose the GPU device just before this frame.
    pub inject_gpu_loss_at: Option<u64>,
    /// Fault injection for tests: a NaN velocity on the first free node before this frame.
    pub inject_nan_at: Option<u64>,
    /// Draw this planned incision on the screenshots (exercise runs; Xpbd scenes).
    pub screenshot_decal: Option<PlanDecal>,
}

/// What a finished run produced.
#[derive(Debug)]
pub struct RunOutcome {
    /// Path of report.json.
    pub report_path: PathBuf,
    /// The report.
    pub report: Report,
}

/// Run a scene headless. A solver failure is returned as `Err` after the report and the
/// snapshots so far have been written.
pub fn run_scene(opts: &RunOptions) -> Result<RunOutcome> {
    let scene = load_scene(&opts.scene)?;
    match &scene.model {
        crate::scene::ModelChoice::MassSpring(ms) => {
            return crate::run_mass_spring::run(&scene, ms, opts);
        }
        crate::scene::ModelChoice::Rheology(rh) => {
            return crate::run_rheology::run(&scene, rh, opts);
        }
        crate::scene::ModelChoice::Xpbd => {}
    }
    if opts.haptic_rate.is_some() {
        bail!(
            "{}: --haptic-rate runs the mass-spring haptic loop; this scene's model is Xpbd",
            opts.scene.display()
        );
    }
    // A recorded stroke is a hand's: the scene gets the tool and cut zone the preview
    // gave it (scene/hand_tool.rs), so the replay is the same physics.
    let driver = match opts.stroke {
        Some(_) => ToolDriver::Hand,
        None => ToolDriver::Scene,
    };
    let BuiltScene {
        tool,
        solver,
        skin,
        material,
        material_name,
        mesh_report,
        pinned_nodes,
        grabbed_nodes,
    } = build_scene_driven(&scene, &opts.scene, opts.threads, driver)?;
    let mut tool = tool;
    if let (Some(t), Some(path)) = (tool.as_mut(), &opts.stroke) {
        t.stroke = Some(incise_scalpel::load_stroke(path)?);
    }
    // The tool and the stroke that drives it this run.
    let tool = tool.and_then(|t| t.stroke.clone().map(|s| (t, s)));
    let mut solver = solver;
    if let Some((t, stroke)) = &tool {
        solver.set_tool(t.contact.clone(), stroke.pose_at(0.0))?;
    }
    let haptic = incise_scalpel::HapticCurve::default();
    let mut recorder = opts
        .record_stroke
        .as_ref()
        .and(tool.as_ref())
        .map(|(_, stroke)| -> Result<incise_scalpel::StrokeRecorder> {
            let mut r = incise_scalpel::StrokeRecorder::new();
            r.push(0.0, stroke.pose_at(0.0))?;
            Ok(r)
        })
        .transpose()?;
    if opts.record_stroke.is_some() && tool.is_none() {
        bail!("--record-stroke: {} has no tool", opts.scene.display());
    }
    let mut shots = match opts.screenshot_every {
        0 => None,
        _ => {
            let shots = Screenshots::new(
                None,
                &solver,
                &skin,
                opts.screenshot_size,
                Default::default(),
            )?;
            let shots = match &tool {
                Some((t, _)) => shots.with_tool(&t.tool),
                None => shots,
            };
            Some(match &opts.screenshot_decal {
                Some(d) => shots.with_decal(d.clone()),
                None => shots,
            })
        }
    };
    let quiet = opts.quiet;
    let mut device_choice = None;
    let mut body = Body::place(solver, opts.device, |m| device_choice = Some(m.to_string()))?;
    if let Some(m) = device_choice.as_ref().filter(|_| !quiet) {
        eprintln!("note: {m}");
    }
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let solver = body.solver();
    let frames = opts
        .frames
        .unwrap_or_else(|| (scene.duration / solver.params().frame_dt).round().max(1.0) as u64);
    let threads = match solver.params().threads {
        0 => rayon::current_num_threads(),
        n => n,
    };
    let lame = solver.lame();
    let mesh = solver.mesh();
    let mut report = Report {
        scene: scene.name.clone(),
        scene_file: opts.scene.display().to_string(),
        model: "xpbd".into(),
        status: "running".into(),
        error: None,
        mesh: MeshInfo {
            nodes: mesh.node_count(),
            tets: mesh.tet_count(),
            reoriented_tets: mesh_report.reoriented_tets,
            colors: solver.color_count(),
            skin_vertices: skin.surface.positions.len(),
            skin_triangles: skin.surface.triangles.len(),
            pinned_nodes,
            grabbed_nodes,
            warnings: mesh_report.warnings.clone(),
        },
        material: Some(MaterialInfo {
            name: material_name,
            values: material,
            mu: lame.mu,
            lambda: lame.lambda,
        }),
        solver: solver.params().clone(),
        threads,
        device: body.device(),
        device_choice,
        tool: tool.as_ref().map(|(t, stroke)| ToolInfo {
            name: t.tool.name().to_string(),
            spheres: t.contact.spheres.len(),
            cutting_spheres: t.contact.spheres.iter().filter(|s| s.cutting).count(),
            sphere_radius: t.contact.spheres.first().map_or(0.0, |s| s.radius),
            boxes: t.contact.boxes.len(),
            friction: t.contact.friction,
            stroke_duration: stroke.duration(),
        }),
        released_tets: Vec::new(),
        warnings: Vec::new(),
        frames: Vec::with_capacity(frames as usize),
        snapshots: Vec::new(),
        rheology: None,
        haptic: None,
        localisation: None,
    };
    let report_path = opts.out.join("report.json");
    let mut pvd: Vec<(f64, String)> = Vec::new();
    if opts.vtu_every > 0 {
        snapshot(&opts.out, body.solver(), 0, &mut pvd)?;
    }
    if let Some(s) = &mut shots {
        s.save(&body, &opts.out.join("frame_00000.png"))?;
    }
    let progress = (!opts.quiet).then(|| Progress::new(frames, 60));
    let mut failure = None;
    let dt = body.solver().params().frame_dt as f64;
    for f in 0..frames {
        if crate::interrupt::requested() {
            failure = Some(RunEnd::Interrupted { frames: f });
            break;
        }
        let t0 = Instant::now();
        if let Some((_, stroke)) = &tool {
            let time = (f + 1) as f64 * dt;
            let pose = stroke.pose_at(time);
            body.move_tool(pose);
            if let Some(r) = &mut recorder {
                r.push(time, pose)?;
            }
        }
        if opts.inject_gpu_loss_at == Some(f) {
            body.inject_device_loss();
        }
        if opts.inject_nan_at == Some(f) {
            body.inject_nan();
        }
        let mut stepped = body.step_frame();
        if let Err(SolverError::Device(msg)) = &stepped {
            let warning = format!(
                "frame {f}: the GPU failed ({msg}); continuing on the CPU from the last completed frame"
            );
            if !opts.quiet {
                eprintln!("warning: {warning}");
            }
            report.warnings.push(warning);
            body = body.into_cpu();
            report.device = format!("{} (after a GPU failure)", body.device());
            stepped = body.step_frame();
        }
        match stepped {
            Ok(stats) => {
                let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
                if let Some(p) = &progress {
                    p.frame(f, || {
                        format!(
                            "max σvM {:.0} Pa, released {}, tool {:.2} N",
                            stats.max_von_mises,
                            stats.released_total,
                            stats.tool_force.length()
                        )
                    });
                }
                let haptic_amplitude = tool
                    .as_ref()
                    .map(|_| haptic.amplitude(stats.tool_force.length()));
                report.frames.push(FrameRecord {
                    haptic_amplitude,
                    stats: FrameData::Xpbd(stats),
                    wall_ms,
                    gpu_ms: body.gpu_frame_ms(),
                });
            }
            Err(e) => {
                failure = Some(RunEnd::Failed(e.to_string()));
                break;
            }
        }
        if opts.vtu_every > 0 && (f + 1) % opts.vtu_every == 0 {
            snapshot(&opts.out, body.solver(), f + 1, &mut pvd)?;
        }
        if (f + 1) % CHECKPOINT_FRAMES == 0 {
            // A run that is killed keeps its report and stroke up to here (status
            // "running"); both are written atomically.
            report.write(&report_path)?;
            if let (Some(r), Some(path)) = (&recorder, &opts.record_stroke) {
                r.clone().finish()?.save(path)?;
            }
        }
        if let Some(s) = shots
            .as_mut()
            .filter(|_| (f + 1) % opts.screenshot_every == 0)
        {
            s.save(&body, &opts.out.join(format!("frame_{:05}.png", f + 1)))?;
        }
    }
    if let Some(p) = &progress {
        p.finish();
    }
    if !pvd.is_empty() {
        write_pvd(&opts.out.join("run.pvd"), &pvd)?;
        report.snapshots = pvd.iter().map(|(_, f)| f.clone()).collect();
    }
    let cut = body.solver().cut();
    report.released_tets = (0..body.solver().mesh().tet_count() as u32)
        .filter(|&t| !cut.is_live(t as usize))
        .collect();
    if let (Some(r), Some(path)) = (recorder, &opts.record_stroke) {
        r.finish()?.save(path)?;
    }
    finish(report, report_path, failure, opts)
}

/// Why a run stopped before its last frame.
#[derive(Debug, Clone)]
pub enum RunEnd {
    /// The solver failed (the error).
    Failed(String),
    /// Ctrl-C or SIGTERM after this many frames.
    Interrupted {
        /// Frames completed.
        frames: u64,
    },
}

/// Record how the run ended in `report` ("completed", "failed" with the error, or
/// "interrupted"), write it, and return the outcome; after a failure, the error naming
/// the scene and saying that the output written so far is kept; after Ctrl-C, an
/// [`Interrupted`](crate::interrupt::Interrupted) error (exit 130).
pub fn finish(
    mut report: Report,
    report_path: PathBuf,
    stopped: Option<RunEnd>,
    opts: &RunOptions,
) -> Result<RunOutcome> {
    let (status, error) = match &stopped {
        None => ("completed", None),
        Some(RunEnd::Failed(e)) => ("failed", Some(e.clone())),
        Some(RunEnd::Interrupted { frames }) => (
            "interrupted",
            Some(format!("interrupted by the user after {frames} frames")),
        ),
    };
    report.status = status.into();
    report.error = error;
    report.write(&report_path)?;
    match stopped {
        None => Ok(RunOutcome {
            report_path,
            report,
        }),
        Some(RunEnd::Failed(e)) => bail!(
            "{}: {e} (output so far kept in {})",
            opts.scene.display(),
            opts.out.display()
        ),
        Some(RunEnd::Interrupted { frames }) => Err(crate::interrupt::Interrupted {
            what: opts.scene.display().to_string(),
            frames,
            out: opts.out.display().to_string(),
        }
        .into()),
    }
}

/// Write `snap_NNNNN.vtu` for frame `frame` and add it to the collection.
pub fn snapshot(
    out: &Path,
    solver: &incise_sim::Solver,
    frame: u64,
    pvd: &mut Vec<(f64, String)>,
) -> Result<()> {
    let name = format!("snap_{frame:05}.vtu");
    let released: Vec<f32> = solver
        .cut()
        .live()
        .iter()
        .map(|&l| if l { 0.0 } else { 1.0 })
        .collect();
    let frame_data = VtuFrame {
        positions: solver.positions(),
        tets: &solver.mesh().tets,
        cell_scalars: vec![("von_mises", solver.von_mises()), ("released", &released)],
        point_vectors: vec![("velocity", solver.velocities())],
        point_scalars: vec![],
    };
    write_vtu(&out.join(&name), &frame_data)?;
    pvd.push((solver.time(), name));
    Ok(())
}
