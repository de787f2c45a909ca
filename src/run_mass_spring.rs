//! `incise run` for mass-spring scenes (PHYSICS.md §2): the tension mass-spring model with
//! a scripted blade stroke. Writes the same report.json frame fields where they mean
//! something for this model (von Mises stress is not computed: null), VTU snapshots and
//! a ParaView collection, like the XPBD runner.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, anyhow};
use glam::{DVec3, Vec3};
use incise_sim::io::{VtuFrame, write_pvd, write_vtu};
use incise_sim::mass_spring::{AxisMask, MassSpringModel, MassSpringParams};
use incise_sim::nakao_cut::measure::counts;
use incise_sim::nakao_cut::{BladePose, Cutter};
use incise_sim::xpbd::FrameStats;
use incise_sim::{Material, TetMesh};

use crate::report::{FrameRecord, MaterialInfo, MeshInfo, Report};
use crate::run::{RunOptions, RunOutcome};
use crate::scene::{MassSpringScene, MaterialChoice, Scene, StrokeSpec, load_materials, raw_mesh};

/// Run the mass-spring scene `scene` (with model settings `ms`) as `opts` asks.
pub fn run(scene: &Scene, ms: &MassSpringScene, opts: &RunOptions) -> Result<RunOutcome> {
    let dir = opts.scene.parent().unwrap_or(Path::new("."));
    let (raw, _) = raw_mesh(&scene.mesh, dir)?;
    let (mesh, mesh_report) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", opts.scene.display()))?;
    let (material, material_name) = material(scene, dir, &opts.scene)?;
    let params = MassSpringParams {
        stiffness: ms.stiffness,
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
        scene: scene.name.clone(),
        scene_file: opts.scene.display().to_string(),
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
        material: MaterialInfo {
            name: material_name,
            values: material,
            mu: lame.mu,
            lambda: lame.lambda,
        },
        solver: scene.solver.clone(),
        threads: 1,
        device: "cpu (mass-spring)".into(),
        frames: Vec::with_capacity(frames as usize),
        snapshots: Vec::new(),
    };
    let total_volume: f64 = (0..model.tet_count())
        .map(|t| model.reference_volume(t))
        .sum();
    let mut cutter = Cutter::new(ms.cut.clone());
    let mut cutting = false;
    let mut pvd: Vec<(f64, String)> = Vec::new();
    if opts.vtu_every > 0 {
        snapshot(&opts.out, &model, 0, &mut pvd)?;
    }
    for f in 0..frames {
        let t0 = Instant::now();
        if let Some(stroke) = &ms.stroke {
            let (pose, progress) = blade_at(stroke, model.time());
            if progress > 0.0 && !cutting && progress < 1.0 {
                cutter.begin(&model, blade_at(stroke, stroke.start as f64).0);
                cutting = true;
            }
            if cutting {
                cutter.advance(&mut model, pose);
                if progress >= 1.0 {
                    cutter.end();
                    cutting = false;
                }
            }
        }
        let steps = model.advance(frame_dt);
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        let volume: f64 = (0..model.tet_count())
            .map(|t| model.current_volume(t))
            .sum();
        report.frames.push(FrameRecord {
            stats: FrameStats {
                frame: f,
                sim_time: model.time(),
                substeps: steps,
                max_von_mises: f32::NAN,
                mean_von_mises: f32::NAN,
                released_now: 0,
                released_total: 0,
                retired_nodes: 0,
                volume_ratio: volume / total_volume,
                kinetic_energy: model.kinetic_energy(),
                solve_ms: wall_ms,
                stress_ms: 0.0,
            },
            wall_ms,
            gpu_ms: None,
        });
        if opts.vtu_every > 0 && (f + 1) % opts.vtu_every == 0 {
            snapshot(&opts.out, &model, f + 1, &mut pvd)?;
        }
    }
    if !pvd.is_empty() {
        write_pvd(&opts.out.join("run.pvd"), &pvd)?;
        report.snapshots = pvd.iter().map(|(_, f)| f.clone()).collect();
    }
    let after = counts(&model);
    report.mesh.nodes = after.nodes;
    report.mesh.tets = after.tets;
    report.mesh.skin_vertices = after.nodes;
    report.mesh.skin_triangles = after.triangles;
    report.status = "completed".into();
    let report_path = opts.out.join("report.json");
    report.write(&report_path)?;
    if !opts.quiet {
        println!(
            "mass-spring: {} nodes, {} tets, {} edges after {} frames",
            after.nodes, after.tets, after.edges, frames
        );
    }
    Ok(RunOutcome {
        report_path,
        report,
    })
}

/// The scene's material, resolving a preset from `materials.ron` beside the scene.
fn material(scene: &Scene, dir: &Path, scene_path: &Path) -> Result<(Material, String)> {
    Ok(match &scene.material {
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
fn blade_at(s: &StrokeSpec, t: f64) -> (BladePose, f64) {
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
fn snapshot(
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
