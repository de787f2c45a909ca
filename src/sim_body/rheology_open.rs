//! Opening a `Rheology` scene (PHYSICS.md §3): every tet edge a three-element element, a
//! preset per region of the mesh, pins, gravity and the optional flat indenter; and the
//! report's head with the materials per region and the RK4 step.

use std::path::Path;

use anyhow::{Context, Result, bail};
use incise_sim::rheology::{
    MaterialMap, MaterialRegion, RegionShape, RheologyBody as Model, RheologyError, RheologyPresets,
};
use incise_sim::{MeshBuildReport, TetMesh};

use super::edge_report::{HeadCounts, edge_method_head};
use super::interface::OpenOptions;
use super::rheology::{Press, RheologyBody};
use crate::report::{RegionMaterialInfo, Report, RheologyInfo};
use crate::scene::Method;
use crate::scene::{RegionSelect, RheologyScene, Scene, SceneError, locate, raw_mesh};

/// Open the rheology scene `scene` (model settings `rh`, file `path`).
pub fn open(
    scene: &Scene,
    rh: &RheologyScene,
    path: &Path,
    opts: &OpenOptions,
) -> Result<(RheologyBody, Report)> {
    refuse(scene, path, opts)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (raw, _) = raw_mesh(&scene.mesh, dir)?;
    let (mesh, mesh_report) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", path.display()))?;
    let (presets_path, presets) = crate::scene::built_in::config_text(dir, &rh.presets)
        .map_err(anyhow::Error::from)
        .and_then(|(file, text)| Ok((file.clone(), RheologyPresets::parse(&text, &file)?)))
        .with_context(|| format!("{}: model.presets", path.display()))?;
    let names = material_names(rh);
    let (materials, map) = materials(&mesh, rh, &presets, &names, path)?;
    let rows = material_rows(&map, &names);
    let mut model =
        Model::new(&mesh, &materials, map).with_context(|| format!("{}: model", path.display()))?;
    let pinned = pin(&mut model, scene, &mesh, path)?;
    model.set_gravity(scene.solver.gravity.as_dvec3());
    let limit = model.stability();
    let mut report = skeleton(scene, path, &mesh, &mesh_report, pinned);
    report.rheology = Some(RheologyInfo {
        presets_file: presets_path.display().to_string(),
        materials: rows,
        stability_limit_s: limit.max_step,
        step_s: limit.safe_step(),
        max_dent_m: 0.0,
        residual_dent_m: 0.0,
    });
    let press = Press::of_scene(&mesh, rh.indenter.as_ref());
    let body = RheologyBody::new(model, mesh, press, scene.solver.frame_dt as f64);
    Ok((body, report))
}

/// What a rheology scene cannot have: the haptic-rate loop, grabs.
fn refuse(scene: &Scene, path: &Path, opts: &OpenOptions) -> Result<()> {
    if opts.haptic_rate.is_some() {
        bail!(
            "{}: --haptic-rate runs the mass-spring haptic loop; this scene's model is Rheology",
            path.display()
        );
    }
    if !scene.grabs.is_empty() {
        bail!(
            "{}: grabs are not supported by the Rheology model (use model.indenter)",
            path.display()
        );
    }
    Ok(())
}

/// Pin the scene's pins; the pinned count.
fn pin(model: &mut Model, scene: &Scene, mesh: &TetMesh, path: &Path) -> Result<usize> {
    let mut pinned = 0;
    for (i, sel) in scene.pins.iter().enumerate() {
        let nodes = sel
            .select(&mesh.rest_positions)
            .with_context(|| format!("{}: pins[{i}]", path.display()))?;
        pinned += nodes.len();
        model.pin(&nodes);
    }
    Ok(pinned)
}

/// The report's head of a rheology run.
fn skeleton(
    scene: &Scene,
    path: &Path,
    mesh: &TetMesh,
    mesh_report: &MeshBuildReport,
    pinned: usize,
) -> Report {
    let counts = HeadCounts {
        nodes: mesh.node_count(),
        tets: mesh.tet_count(),
        skin_vertices: 0,
        skin_triangles: 0,
        pinned,
    };
    edge_method_head(
        scene,
        path,
        ("rheology", Method::Rheology),
        mesh_report,
        counts,
    )
}

/// The material list: the default first, then one per region (duplicates are harmless).
fn material_names(rh: &RheologyScene) -> Vec<String> {
    let mut names = vec![rh.material.clone()];
    names.extend(rh.regions.iter().map(|r| r.material.clone()));
    names
}

/// The presets of `names` and which edge and tet takes which; a bad name or region is an
/// error naming the scene file, line and field.
fn materials(
    mesh: &TetMesh,
    rh: &RheologyScene,
    presets: &RheologyPresets,
    names: &[String],
    path: &Path,
) -> Result<(Vec<incise_sim::rheology::RheologyMaterial>, MaterialMap)> {
    let scene_text = std::fs::read_to_string(path).unwrap_or_default();
    let field_error = |field: String, msg: String| SceneError::Value {
        path: path.to_path_buf(),
        line: locate(&scene_text, &field),
        field,
        msg,
    };
    let mut materials = Vec::with_capacity(names.len());
    for (k, name) in names.iter().enumerate() {
        let field = match k {
            0 => "model.material".to_string(),
            k => format!("model.regions[{}].material", k - 1),
        };
        let m = presets
            .get(name)
            .map_err(|e| field_error(field, format!("is unknown: {e}")))?;
        materials.push(m);
    }
    let regions: Vec<MaterialRegion> = rh
        .regions
        .iter()
        .enumerate()
        .map(|(r, spec)| MaterialRegion {
            shape: match &spec.tets {
                RegionSelect::Nodes(sel) => RegionShape::Nodes(sel.clone()),
                RegionSelect::Tets(list) => RegionShape::Tets(list.clone()),
            },
            material: r + 1,
        })
        .collect();
    let edges = incise_sim::mesh::EdgeList::of_mesh(mesh);
    let map = MaterialMap::from_regions(mesh, &edges, 0, &regions, materials.len()).map_err(
        |e| match e {
            RheologyError::EmptyRegion { region, .. } => field_error(
                format!("model.regions[{region}].tets"),
                format!("is unusable: {e}"),
            ),
            RheologyError::Selection { ref what, .. } => {
                let region = what
                    .rsplit(' ')
                    .next()
                    .and_then(|r| r.parse::<usize>().ok())
                    .unwrap_or(0);
                field_error(
                    format!("model.regions[{region}].tets"),
                    format!("is unusable: {e}"),
                )
            }
            e => field_error("model.regions".into(), e.to_string()),
        },
    )?;
    Ok((materials, map))
}

/// Tet and edge counts per material (index 0: the default, k: region k − 1).
fn material_rows(map: &MaterialMap, names: &[String]) -> Vec<RegionMaterialInfo> {
    let count = |list: &[u32], k: usize| list.iter().filter(|&&m| m as usize == k).count();
    names
        .iter()
        .enumerate()
        .map(|(k, name)| RegionMaterialInfo {
            region: match k {
                0 => "default".into(),
                k => format!("regions[{}]", k - 1),
            },
            preset: name.clone(),
            tets: count(&map.tet_material, k),
            edges: count(&map.edge_material, k),
        })
        .collect()
}
