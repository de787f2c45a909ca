//! Opening a `MassSpring` scene as a Nakao body (PHYSICS.md §2): the mesh, the model with
//! the scene's stiffness, damping and tension, its pins and held axes, and the report's
//! head. Frame by frame ([`NakaoBody`]) or, with a haptic rate, on its own thread
//! ([`NakaoHapticBody`]).

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use incise_sim::mass_spring::{AxisMask, MassSpringModel, MassSpringParams};
use incise_sim::nakao_cut::measure::counts;
use incise_sim::{MeshBuildReport, TetMesh};

use super::edge_report::{HeadCounts, edge_method_head};
use super::interface::{OpenOptions, SimBody};
use super::nakao::NakaoBody;
use super::nakao_haptic::NakaoHapticBody;
use crate::report::{MaterialInfo, Report};
use crate::scene::Method;
use crate::scene::{MassSpringScene, Scene, raw_mesh, scene_material};

/// Open the mass-spring scene `scene` (model settings `ms`, file `path`) as `opts` asks.
pub fn open(
    scene: &Scene,
    ms: &MassSpringScene,
    path: &Path,
    opts: &OpenOptions,
) -> Result<(Box<dyn SimBody>, Report)> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let (raw, _) = raw_mesh(&scene.mesh, dir)?;
    let (mesh, mesh_report) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", path.display()))?;
    let (material, material_name) = scene_material(scene, path)?;
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
        .with_context(|| format!("{}: model", path.display()))?;
    let pinned = fix(&mut model, scene, ms, &mesh, path)?;
    let mut report = skeleton(scene, path, &model, &mesh_report, pinned);
    report.material = Some(MaterialInfo {
        name: material_name,
        values: material,
        mu: material.lame().mu,
        lambda: material.lame().lambda,
    });
    let frame_dt = scene.solver.frame_dt as f64;
    let body: Box<dyn SimBody> = match opts.haptic_rate {
        Some(_) if opts.stroke.is_some() => bail!(
            "{}: --haptic-rate moves the haptic tool along model.stroke; a stroke file drives \
             the frame-by-frame body only",
            path.display()
        ),
        Some(rate) => {
            let stroke = ms.stroke.clone().ok_or_else(|| {
                anyhow!(
                    "{}: --haptic-rate moves the haptic tool along model.stroke, and this \
                     scene has none",
                    path.display()
                )
            })?;
            Box::new(NakaoHapticBody::spawn(model, ms, stroke, rate, frame_dt))
        }
        None => {
            let mut body = NakaoBody::new(model, ms, frame_dt);
            if let Some(free) = &opts.free_nodes {
                body = body.with_free_nodes(free.clone());
            }
            match &opts.stroke {
                Some(file) => Box::new(body.with_stroke(incise_scalpel::load_stroke(file)?)),
                None => Box::new(body),
            }
        }
    };
    Ok((body, report))
}

/// Pin the scene's pins on every axis and hold its `hold` sets on theirs; the pinned count.
fn fix(
    model: &mut MassSpringModel,
    scene: &Scene,
    ms: &MassSpringScene,
    mesh: &TetMesh,
    path: &Path,
) -> Result<usize> {
    let rest = &mesh.rest_positions;
    let mut pinned = 0;
    for (i, sel) in scene.pins.iter().enumerate() {
        let nodes = sel
            .select(rest)
            .with_context(|| format!("{}: pins[{i}]", path.display()))?;
        pinned += nodes.len();
        model.fix(&nodes, AxisMask::ALL)?;
    }
    for (i, h) in ms.hold.iter().enumerate() {
        let nodes = h
            .nodes
            .select(rest)
            .with_context(|| format!("{}: model.hold[{i}].nodes", path.display()))?;
        let axes = [(h.x, AxisMask::X), (h.y, AxisMask::Y), (h.z, AxisMask::Z)]
            .into_iter()
            .filter(|(on, _)| *on)
            .fold(AxisMask::NONE, |m, (_, a)| m.union(a));
        model.fix(&nodes, axes)?;
    }
    Ok(pinned)
}

/// The report's head of a Nakao run.
fn skeleton(
    scene: &Scene,
    path: &Path,
    model: &MassSpringModel,
    mesh_report: &MeshBuildReport,
    pinned: usize,
) -> Report {
    let counts = HeadCounts {
        nodes: model.node_count(),
        tets: model.tet_count(),
        skin_vertices: model.node_count(),
        skin_triangles: counts(model).triangles,
        pinned,
    };
    edge_method_head(
        scene,
        path,
        ("mass-spring", Method::Nakao),
        mesh_report,
        counts,
    )
}
