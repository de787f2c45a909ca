//! `incise run`: the headless runner. Steps a scene, writes report.json, .vtu snapshots and
//! a .pvd collection; on a solver failure the output written so far is kept and the report
//! says what failed.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use incise_sim::io::{VtuFrame, write_pvd, write_vtu};

use crate::body::{Body, DeviceChoice};
use crate::progress::Progress;
use crate::report::{FrameData, FrameRecord, MaterialInfo, MeshInfo, Report};
use crate::scene::{BuiltScene, build_scene, load_scene};
use crate::screenshots::{ImageSize, Screenshots};

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
    let BuiltScene {
        solver,
        skin,
        material,
        material_name,
        mesh_report,
        pinned_nodes,
        grabbed_nodes,
    } = build_scene(&scene, &opts.scene, opts.threads)?;
    let mut shots = match opts.screenshot_every {
        0 => None,
        _ => Some(Screenshots::new(
            None,
            &solver,
            &skin,
            opts.screenshot_size,
            Default::default(),
        )?),
    };
    let quiet = opts.quiet;
    let mut body = Body::place(solver, opts.device, |m| {
        if !quiet {
            eprintln!("note: {m}");
        }
    })?;
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
        frames: Vec::with_capacity(frames as usize),
        snapshots: Vec::new(),
        rheology: None,
        haptic: None,
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
    for f in 0..frames {
        let t0 = Instant::now();
        match body.step_frame() {
            Ok(stats) => {
                let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
                if let Some(p) = &progress {
                    p.frame(f, || {
                        format!(
                            "max σvM {:.0} Pa, released {}",
                            stats.max_von_mises, stats.released_total
                        )
                    });
                }
                report.frames.push(FrameRecord {
                    stats: FrameData::Xpbd(stats),
                    wall_ms,
                    gpu_ms: body.gpu_frame_ms(),
                });
            }
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
        if opts.vtu_every > 0 && (f + 1) % opts.vtu_every == 0 {
            snapshot(&opts.out, body.solver(), f + 1, &mut pvd)?;
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
    report.status = if failure.is_some() {
        "failed"
    } else {
        "completed"
    }
    .into();
    report.error = failure.as_ref().map(|e| e.to_string());
    report.write(&report_path)?;
    if let Some(e) = failure {
        bail!(
            "{}: {e} (output so far kept in {})",
            opts.scene.display(),
            opts.out.display()
        );
    }
    Ok(RunOutcome {
        report_path,
        report,
    })
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
