//! `incise run` for rheology scenes (PHYSICS.md §3): every tet edge a three-element
//! element, a preset per region of the mesh, integrated with RK4 under the explicit
//! stability limit; optionally pressed by a flat indenter. Writes report.json (with the
//! dent of the probe node under the indenter and the materials per region), VTU snapshots
//! and a ParaView collection.

use crate::run::RunEnd;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use glam::{DVec3, Vec3};
use incise_sim::TetMesh;
use incise_sim::io::{VtuFrame, write_pvd, write_vtu};
use incise_sim::rheology::{
    FlatIndenter, MaterialMap, MaterialRegion, PressSchedule, RegionShape, RheologyBody,
    RheologyError, RheologyPresets,
};

use crate::report::{
    EdgeFrameStats, FrameData, FrameRecord, MeshInfo, RegionMaterialInfo, Report, RheologyInfo,
};
use crate::run::{RunOptions, RunOutcome};
use crate::scene::{RegionSelect, RheologyScene, Scene, SceneError, locate, raw_mesh};

/// Run the rheology scene `scene` (with model settings `rh`) as `opts` asks.
pub fn run(scene: &Scene, rh: &RheologyScene, opts: &RunOptions) -> Result<RunOutcome> {
    if opts.haptic_rate.is_some() {
        bail!(
            "{}: --haptic-rate runs the mass-spring haptic loop; this scene's model is Rheology",
            opts.scene.display()
        );
    }
    let dir = opts.scene.parent().unwrap_or(Path::new("."));
    let (raw, _) = raw_mesh(&scene.mesh, dir)?;
    let (mesh, mesh_report) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", opts.scene.display()))?;
    let presets_path = dir.join(&rh.presets);
    let presets = RheologyPresets::load(&presets_path)
        .with_context(|| format!("{}: model.presets", opts.scene.display()))?;
    let scene_text = std::fs::read_to_string(&opts.scene).unwrap_or_default();
    let field_error = |field: String, msg: String| SceneError::Value {
        path: opts.scene.clone(),
        line: locate(&scene_text, &field),
        field,
        msg,
    };
    // Material list: the default first, then one per region (duplicates are harmless).
    let mut names = vec![rh.material.clone()];
    names.extend(rh.regions.iter().map(|r| r.material.clone()));
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
    let edges = incise_sim::mesh::EdgeList::of_mesh(&mesh);
    let map = MaterialMap::from_regions(&mesh, &edges, 0, &regions, materials.len()).map_err(
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
    let material_rows = material_rows(&map, &names);
    let mut body = RheologyBody::new(&mesh, &materials, map)
        .with_context(|| format!("{}: model", opts.scene.display()))?;
    let rest = &mesh.rest_positions;
    let mut pinned = 0;
    for (i, sel) in scene.pins.iter().enumerate() {
        let nodes = sel
            .select(rest)
            .with_context(|| format!("{}: pins[{i}]", opts.scene.display()))?;
        pinned += nodes.len();
        body.pin(&nodes);
    }
    if !scene.grabs.is_empty() {
        bail!(
            "{}: grabs are not supported by the Rheology model (use model.indenter)",
            opts.scene.display()
        );
    }
    body.set_gravity(scene.solver.gravity.as_dvec3());
    let (lo, hi) = incise_sim::mesh::bounds(rest);
    let top = hi.z as f64;
    let centre = match &rh.indenter {
        Some(ind) => ind.centre,
        None => glam::DVec2::new(0.5 * (lo.x + hi.x) as f64, 0.5 * (lo.y + hi.y) as f64),
    };
    let probe = probe_node(&mesh, top, centre);
    let schedule = rh.indenter.as_ref().map(|ind| PressSchedule {
        depth: ind.depth,
        press: ind.press,
        hold: ind.hold,
        lift: ind.lift,
    });
    if let (Some(ind), Some(schedule)) = (&rh.indenter, schedule) {
        // Every node can touch the face: it only pushes those under it and above it.
        body.set_indenter(Some(FlatIndenter {
            centre: ind.centre.to_array(),
            half_size: ind.half_size.to_array(),
            rest_top: top,
            schedule,
            candidates: (0..mesh.node_count() as u32).collect(),
        }));
    }
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let frame_dt = scene.solver.frame_dt as f64;
    let frames = opts
        .frames
        .unwrap_or_else(|| (scene.duration as f64 / frame_dt).round().max(1.0) as u64);
    let limit = body.stability();
    let mut report = Report {
        tool: None,
        released_tets: Vec::new(),
        warnings: Vec::new(),
        scene: scene.name.clone(),
        scene_file: opts.scene.display().to_string(),
        model: "rheology".into(),
        status: "running".into(),
        error: None,
        mesh: MeshInfo {
            nodes: mesh.node_count(),
            tets: mesh.tet_count(),
            reoriented_tets: mesh_report.reoriented_tets,
            colors: 0,
            skin_vertices: 0,
            skin_triangles: 0,
            pinned_nodes: pinned,
            grabbed_nodes: 0,
            warnings: mesh_report.warnings.clone(),
        },
        material: None,
        solver: scene.solver.clone(),
        threads: 1,
        device: "cpu (rheology)".into(),
        device_choice: None,
        frames: Vec::with_capacity(frames as usize),
        snapshots: Vec::new(),
        rheology: Some(RheologyInfo {
            presets_file: presets_path.display().to_string(),
            materials: material_rows,
            stability_limit_s: limit.max_step,
            step_s: limit.safe_step(),
            max_dent_m: 0.0,
            residual_dent_m: 0.0,
        }),
        haptic: None,
        localisation: None,
    };
    let rest_volume: f64 = mesh.rest_volume.iter().map(|&v| v as f64).sum();
    let report_path = opts.out.join("report.json");
    let mut pvd: Vec<(f64, String)> = Vec::new();
    if opts.vtu_every > 0 {
        snapshot(&opts.out, &mesh, &body, 0, &mut pvd)?;
    }
    let mut failure = None;
    let (mut max_dent, mut dent) = (0.0f64, 0.0f64);
    for f in 0..frames {
        if crate::interrupt::requested() {
            failure = Some(RunEnd::Interrupted { frames: f });
            break;
        }
        let t0 = Instant::now();
        let steps = match body.advance(frame_dt) {
            Ok(n) => n,
            Err(e) => {
                failure = Some(RunEnd::Failed(e.to_string()));
                break;
            }
        };
        let solve_ms = t0.elapsed().as_secs_f64() * 1e3;
        let positions = body.positions();
        dent = rest[probe].z as f64 - positions[probe].z;
        max_dent = max_dent.max(dent);
        report.frames.push(FrameRecord {
            haptic_amplitude: None,
            stats: FrameData::Edges(EdgeFrameStats {
                frame: f,
                sim_time: body.time(),
                substeps: steps as u64,
                volume_ratio: volume(&mesh.tets, &positions) / rest_volume,
                max_displacement: max_displacement(rest, &positions),
                kinetic_energy: Some(body.kinetic_energy()),
                solve_ms: Some(solve_ms),
                tool_force: None,
                haptic_loops: None,
                indenter_depth: schedule.map(|s| s.depth_at(body.time()).0),
                dent_depth: Some(dent),
                ..EdgeFrameStats::default()
            }),
            wall_ms: t0.elapsed().as_secs_f64() * 1e3,
            gpu_ms: None,
        });
        if opts.vtu_every > 0 && (f + 1) % opts.vtu_every == 0 {
            snapshot(&opts.out, &mesh, &body, f + 1, &mut pvd)?;
        }
    }
    if !pvd.is_empty() {
        write_pvd(&opts.out.join("run.pvd"), &pvd)?;
        report.snapshots = pvd.iter().map(|(_, f)| f.clone()).collect();
    }
    if let Some(info) = &mut report.rheology {
        info.max_dent_m = max_dent;
        info.residual_dent_m = dent;
    }
    crate::run::finish(report, report_path, failure, opts)
}

/// Tet and edge counts per material (index 0: the default, k: region k − 1).
fn material_rows(map: &MaterialMap, names: &[String]) -> Vec<RegionMaterialInfo> {
    names
        .iter()
        .enumerate()
        .map(|(k, name)| RegionMaterialInfo {
            region: match k {
                0 => "default".into(),
                k => format!("regions[{}]", k - 1),
            },
            preset: name.clone(),
            tets: map
                .tet_material
                .iter()
                .filter(|&&m| m as usize == k)
                .count(),
            edges: map
                .edge_material
                .iter()
                .filter(|&&m| m as usize == k)
                .count(),
        })
        .collect()
}

/// The node on the top plane (rest z within 1 µm of `top`) nearest `centre` in x, y.
fn probe_node(mesh: &TetMesh, top: f64, centre: glam::DVec2) -> usize {
    let d = |i: usize| {
        let p = mesh.rest_positions[i].as_dvec3();
        (p.truncate() - centre).length()
    };
    (0..mesh.node_count())
        .filter(|&i| mesh.rest_positions[i].z as f64 >= top - 1e-6)
        .min_by(|&a, &b| d(a).total_cmp(&d(b)))
        .expect("a mesh has a highest node")
}

/// Total volume of `tets` at `x`, m³.
fn volume(tets: &[[u32; 4]], x: &[DVec3]) -> f64 {
    tets.iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|i| x[i as usize]);
            (b - a).cross(c - a).dot(d - a) / 6.0
        })
        .sum()
}

/// Largest distance of a node from its rest position, m.
fn max_displacement(rest: &[Vec3], x: &[DVec3]) -> f64 {
    rest.iter()
        .zip(x)
        .map(|(r, p)| (*p - r.as_dvec3()).length())
        .fold(0.0, f64::max)
}

/// Write `snap_NNNNN.vtu` (per tet: material index; per node: velocity) and list it.
fn snapshot(
    out: &Path,
    mesh: &TetMesh,
    body: &RheologyBody,
    frame: u64,
    pvd: &mut Vec<(f64, String)>,
) -> Result<()> {
    let name = format!("snap_{frame:05}.vtu");
    let positions: Vec<Vec3> = body.positions().iter().map(|p| p.as_vec3()).collect();
    let velocity: Vec<Vec3> = (0..body.node_count())
        .map(|i| body.velocity(i).as_vec3())
        .collect();
    let material: Vec<f32> = body
        .material_map()
        .tet_material
        .iter()
        .map(|&m| m as f32)
        .collect();
    let frame_data = VtuFrame {
        positions: &positions,
        tets: &mesh.tets,
        cell_scalars: vec![("material", &material)],
        point_vectors: vec![("velocity", &velocity)],
        point_scalars: vec![],
    };
    let path: PathBuf = out.join(&name);
    write_vtu(&path, &frame_data).map_err(|e| anyhow!("{}: {e}", path.display()))?;
    pvd.push((body.time(), name));
    Ok(())
}
