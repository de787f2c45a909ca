//! `incise run` for mass-spring scenes (PHYSICS.md §2): the tension mass-spring model with
//! a scripted blade stroke. Writes the quantities this model has to report.json (volume,
//! displacement, kinetic energy; it computes no stress tensor, so no von Mises field), VTU
//! snapshots and a ParaView collection, like the XPBD runner.
//!
//! With `--haptic-rate HZ` the localised loop runs on its own thread at that rate
//! (PHYSICS.md §2.6, [`HapticLoop`]), its tool tip at the middle of the scene's blade
//! edge, and cuts along the stroke in that thread, while this thread runs the report loop
//! in real time at the scene's frame rate and records the tool force, loop count and
//! snapshot figures the haptic thread publishes.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use glam::{DVec3, Vec3};
use incise_sim::io::{VtuFrame, write_pvd, write_vtu};
use incise_sim::mass_spring::{
    AxisMask, HapticConfig, HapticLoop, LocalLoopParams, MassSpringModel, MassSpringParams,
};
use incise_sim::nakao_cut::BladePose;
use incise_sim::nakao_cut::measure::counts;
use incise_sim::{Material, TetMesh};

use crate::report::{
    EdgeFrameStats, FrameData, FrameRecord, HapticInfo, MaterialInfo, MeshInfo, Report,
};
use crate::run::{RunEnd, RunOptions, RunOutcome};
use crate::scene::{
    Localisation, MassSpringScene, MaterialChoice, Scene, StrokeSpec, load_materials, raw_mesh,
};

/// Run the mass-spring scene `scene` (with model settings `ms`) as `opts` asks.
pub fn run(scene: &Scene, ms: &MassSpringScene, opts: &RunOptions) -> Result<RunOutcome> {
    let dir = opts.scene.parent().unwrap_or(Path::new("."));
    let (raw, _) = raw_mesh(&scene.mesh, dir)?;
    let (mesh, mesh_report) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", opts.scene.display()))?;
    let (material, material_name) = material(scene, dir, &opts.scene)?;
    let params = MassSpringParams {
        stiffness: ms.stiffness,
        stiffness_law: ms.stiffness_law,
        damping: ms.damping,
        density: material.density as f64,
        gravity: scene.solver.gravity.as_dvec3(),
        tension: ms.tension,
        ..MassSpringParams::default()
    };
    let mut model = MassSpringModel::new(&mesh, params)
        .with_context(|| format!("{}: model", opts.scene.display()))?;
    let rest = &mesh.rest_positions;
    let mut pinned = 0;
    for (i, sel) in scene.pins.iter().enumerate() {
        let nodes = sel
            .select(rest)
            .with_context(|| format!("{}: pins[{i}]", opts.scene.display()))?;
        pinned += nodes.len();
        model.fix(&nodes, AxisMask::ALL)?;
    }
    for (i, h) in ms.hold.iter().enumerate() {
        let nodes = h
            .nodes
            .select(rest)
            .with_context(|| format!("{}: model.hold[{i}].nodes", opts.scene.display()))?;
        let axes = [(h.x, AxisMask::X), (h.y, AxisMask::Y), (h.z, AxisMask::Z)]
            .into_iter()
            .filter(|(on, _)| *on)
            .fold(AxisMask::NONE, |m, (_, a)| m.union(a));
        model.fix(&nodes, axes)?;
    }
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let frame_dt = scene.solver.frame_dt as f64;
    let frames = opts
        .frames
        .unwrap_or_else(|| (scene.duration as f64 / frame_dt).round().max(1.0) as u64);
    let lame = material.lame();
    let mut report = Report {
        tool: None,
        released_tets: Vec::new(),
        warnings: Vec::new(),
        scene: scene.name.clone(),
        scene_file: opts.scene.display().to_string(),
        model: "mass-spring".into(),
        status: "running".into(),
        error: None,
        mesh: MeshInfo {
            nodes: model.node_count(),
            tets: model.tet_count(),
            reoriented_tets: mesh_report.reoriented_tets,
            colors: 0,
            skin_vertices: model.node_count(),
            skin_triangles: counts(&model).triangles,
            pinned_nodes: pinned,
            grabbed_nodes: 0,
            warnings: mesh_report.warnings.clone(),
        },
        material: Some(MaterialInfo {
            name: material_name,
            values: material,
            mu: lame.mu,
            lambda: lame.lambda,
        }),
        solver: scene.solver.clone(),
        threads: 1,
        device: "cpu (mass-spring)".into(),
        device_choice: None,
        frames: Vec::with_capacity(frames as usize),
        snapshots: Vec::new(),
        rheology: None,
        haptic: None,
        localisation: None,
    };
    let total_volume: f64 = (0..model.tet_count())
        .map(|t| model.reference_volume(t))
        .sum();
    let mut pvd: Vec<(f64, String)> = Vec::new();
    if opts.vtu_every > 0 {
        snapshot(&opts.out, &model, 0, &mut pvd)?;
    }
    let model = match opts.haptic_rate {
        Some(rate) => {
            let stroke = ms.stroke.as_ref().ok_or_else(|| {
                anyhow!(
                    "{}: --haptic-rate moves the haptic tool along model.stroke, and this \
                     scene has none",
                    opts.scene.display()
                )
            })?;
            let (model, haptic) =
                run_haptic(model, ms, stroke, rate, frame_dt, frames, &mut report)?;
            report.haptic = Some(haptic);
            model
        }
        None => crate::mass_spring_frames::run_frames(
            model,
            ms,
            frame_dt,
            frames,
            total_volume,
            opts,
            &mut report,
            &mut pvd,
        )?,
    };
    if !pvd.is_empty() {
        write_pvd(&opts.out.join("run.pvd"), &pvd)?;
        report.snapshots = pvd.iter().map(|(_, f)| f.clone()).collect();
    }
    let after = counts(&model);
    report.mesh.nodes = after.nodes;
    report.mesh.tets = after.tets;
    report.mesh.skin_vertices = after.nodes;
    report.mesh.skin_triangles = after.triangles;
    // Ctrl-C stops the frame loops; the run then ends as every runner does.
    let stopped = crate::interrupt::requested().then_some(RunEnd::Interrupted {
        frames: report.frames.len() as u64,
    });
    if !opts.quiet && stopped.is_none() {
        eprintln!(
            "mass-spring: {} nodes, {} tets, {} edges after {} frames",
            after.nodes, after.tets, after.edges, frames
        );
    }
    crate::run::finish(report, opts.out.join("report.json"), stopped, opts)
}

/// The haptic-rate run: the local loop on its own thread at `rate` Hz with its tool at
/// the middle of the blade edge, cutting along the stroke; this thread wakes every
/// `frame_dt` of wall time for `frames` frames, moves the tool and the blade to where the
/// stroke is at the haptic thread's simulated time, and records what that thread
/// published. Returns the model and the measured loop figures.
fn run_haptic(
    model: MassSpringModel,
    ms: &MassSpringScene,
    stroke: &StrokeSpec,
    rate: f64,
    frame_dt: f64,
    frames: u64,
    report: &mut Report,
) -> Result<(MassSpringModel, HapticInfo)> {
    let tool = |pose: BladePose| (pose.heel + pose.tip) * 0.5;
    let config = HapticConfig {
        rate_hz: rate,
        publish_hz: 1.0 / frame_dt,
        local: haptic_localisation(ms.localisation),
        cut: ms.cut.clone(),
        ..HapticConfig::default()
    };
    let start = Instant::now();
    let haptic = HapticLoop::spawn(model, config);
    haptic.set_tool(Some(tool(blade_at(stroke, 0.0).0)));
    let (mut previous_loops, mut max_force, mut blade_down) = (0u64, 0.0f64, false);
    for f in 0..frames {
        if crate::interrupt::requested() {
            break;
        }
        let deadline = start + std::time::Duration::from_secs_f64((f + 1) as f64 * frame_dt);
        let now = Instant::now();
        if now < deadline {
            std::thread::sleep(deadline - now);
        }
        let t0 = Instant::now();
        let latest = haptic.latest();
        let (pose, progress) = blade_at(stroke, latest.sim_time);
        haptic.set_tool(Some(tool(pose)));
        // The stroke's first pose places the blade; later ones cut; its end lifts it.
        if progress > 0.0 && progress < 1.0 {
            let pose = if blade_down {
                pose
            } else {
                blade_at(stroke, stroke.start as f64).0
            };
            haptic.set_blade(Some(pose));
            blade_down = true;
        } else if blade_down && progress >= 1.0 {
            haptic.set_blade(Some(pose));
            blade_down = false;
        } else {
            haptic.set_blade(None);
        }
        let force = latest.tool_force;
        max_force = max_force.max(force.length());
        report.frames.push(FrameRecord {
            haptic_amplitude: None,
            stats: FrameData::Edges(EdgeFrameStats {
                frame: f,
                sim_time: latest.sim_time,
                substeps: latest.loops - previous_loops,
                volume_ratio: latest.volume_ratio,
                max_displacement: latest.max_displacement,
                kinetic_energy: Some(latest.kinetic_energy),
                solve_ms: None,
                tool_force: Some(force.to_array()),
                haptic_loops: Some(latest.loops),
                ..EdgeFrameStats::default()
            }),
            wall_ms: t0.elapsed().as_secs_f64() * 1e3,
            gpu_ms: None,
        });
        previous_loops = latest.loops;
    }
    let last = haptic.latest();
    let wall_s = start.elapsed().as_secs_f64();
    let model = haptic
        .stop()
        .map_err(|_| anyhow!("the haptic thread panicked"))?;
    let info = HapticInfo {
        requested_hz: rate,
        loops: last.loops,
        wall_s,
        achieved_hz: last.loops as f64 / wall_s,
        overruns: last.overruns,
        sim_time: last.sim_time,
        snapshots: last.snapshots,
        report_hz: 1.0 / frame_dt,
        cut_advances: last.cut_advances,
        last_tool_force: last.tool_force.to_array(),
        max_tool_force: max_force.max(last.tool_force.length()),
    };
    if !(info.achieved_hz.is_finite() && info.last_tool_force.iter().all(|f| f.is_finite())) {
        bail!("the haptic loop produced a non-finite rate or tool force: {info:?}");
    }
    Ok((model, info))
}

/// The haptic loop's localisation: the scene's level or budget; `Whole` keeps the loop's
/// default level 4 (a 1 kHz loop cannot integrate a large mesh whole).
fn haptic_localisation(l: Localisation) -> LocalLoopParams {
    match l {
        Localisation::Whole => LocalLoopParams::default(),
        Localisation::Level(d) => LocalLoopParams {
            max_level: d,
            ..LocalLoopParams::default()
        },
        Localisation::Budget(ms) => LocalLoopParams {
            budget_ms: Some(ms),
            max_level: u32::MAX,
            ..LocalLoopParams::default()
        },
    }
}

/// Largest distance of a node from its reference position, m.
pub(crate) fn max_displacement(reference: &[DVec3], x: &[DVec3]) -> f64 {
    reference
        .iter()
        .zip(x)
        .map(|(r, p)| (*p - *r).length())
        .fold(0.0, f64::max)
}

/// The scene's material, resolving a preset from `materials.ron` beside the scene.
fn material(scene: &Scene, dir: &Path, scene_path: &Path) -> Result<(Material, String)> {
    Ok(match &scene.material {
        MaterialChoice::Unset => bail!("{}: material is missing", scene_path.display()),
        MaterialChoice::Custom(m) => (*m, "custom".to_string()),
        MaterialChoice::Preset(name) => {
            let file = dir.join("materials.ron");
            let presets = load_materials(&file)?;
            let m = presets.get(name).ok_or_else(|| {
                anyhow!(
                    "{}: material preset \"{name}\" is not in {}",
                    scene_path.display(),
                    file.display()
                )
            })?;
            (*m, name.clone())
        }
    })
}

/// The blade pose at time `t` and the stroke's progress (0 before it starts, 1 at its end).
pub(crate) fn blade_at(s: &StrokeSpec, t: f64) -> (BladePose, f64) {
    let length = s.travel.length() as f64;
    let progress = if length > 0.0 {
        ((t - s.start as f64) * s.speed as f64 / length).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let d: DVec3 = s.travel.as_dvec3() * progress;
    (
        BladePose {
            heel: s.heel.as_dvec3() + d,
            tip: s.tip.as_dvec3() + d,
        },
        progress,
    )
}

/// Write `snap_NNNNN.vtu` (per node: velocity; per tet: cut faces) and list it.
pub(crate) fn snapshot(
    out: &Path,
    m: &MassSpringModel,
    frame: u64,
    pvd: &mut Vec<(f64, String)>,
) -> Result<()> {
    let name = format!("snap_{frame:05}.vtu");
    let positions: Vec<Vec3> = m.positions().iter().map(|p| p.as_vec3()).collect();
    let velocity: Vec<Vec3> = m.velocities().iter().map(|v| v.as_vec3()).collect();
    let cut: Vec<f32> = m
        .tet_cut_faces()
        .iter()
        .map(|f| f.count_ones() as f32)
        .collect();
    let frame_data = VtuFrame {
        positions: &positions,
        tets: m.tets(),
        cell_scalars: vec![("cut_faces", &cut)],
        point_vectors: vec![("velocity", &velocity)],
        point_scalars: vec![],
    };
    write_vtu(&out.join(&name), &frame_data)?;
    pvd.push((m.time(), name));
    Ok(())
}
