//! Turning a scene into a ready solver: mesh, skin, material, pins, grabs.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use incise_sim::grab::Grab;
use incise_sim::skin::Skin;
use incise_sim::{Material, MeshBuildReport, RawMesh, Solver, TetMesh, TriSurface, generate, io};

use super::{Generator, MeshSource, Scene, SkinSource};

/// A scene with its mesh built and its solver set up.
pub struct BuiltScene {
    /// The solver, at rest, with pins and grabs applied.
    pub solver: Solver,
    /// The skin embedded in the tets.
    pub skin: Skin,
    /// The material in use (resolved preset).
    pub material: Material,
    /// Name of the material preset, or "custom".
    pub material_name: String,
    /// What building the mesh changed (re-oriented tets, reader warnings).
    pub mesh_report: MeshBuildReport,
    /// Pinned node count.
    pub pinned_nodes: usize,
    /// Grabbed node count.
    pub grabbed_nodes: usize,
    /// The scalpel and its stroke, when the scene has one (attached to the solver at the
    /// stroke's first pose); with [`ToolDriver::Hand`] always (the built-in blade when the
    /// scene names none, not attached: the hand places it).
    pub tool: Option<SceneTool>,
}

/// A scene's scalpel as loaded.
pub struct SceneTool {
    /// The tool model (geometry, render mesh).
    pub tool: incise_scalpel::Tool,
    /// What the solver sees of it (spheres sized for this mesh, body boxes).
    pub contact: incise_sim::contact::ContactTool,
    /// The scene's stroke (`None`: a hand-driven tool the scene does not script).
    pub stroke: Option<incise_scalpel::Stroke>,
}

/// Who moves a scene's scalpel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolDriver {
    /// The scene's own stroke (or no tool at all).
    Scene,
    /// A hand: the preview's mouse or a recorded stroke. Every scene gets a tool (the
    /// built-in No. 10 when it names none); the scene's cut zone stays (see `hand_tool`).
    Hand,
}

/// Build `scene` (read from `scene_path`, whose folder anchors relative paths); presets
/// come from `materials.ron` beside the scene file.
pub fn build_scene(scene: &Scene, scene_path: &Path, threads: Option<usize>) -> Result<BuiltScene> {
    build_scene_driven(scene, scene_path, threads, ToolDriver::Scene)
}

/// [`build_scene`] for a tool moved by `driver`.
pub fn build_scene_driven(
    scene: &Scene,
    scene_path: &Path,
    threads: Option<usize>,
    driver: ToolDriver,
) -> Result<BuiltScene> {
    if let Some(model) = scene.model.non_xpbd_name() {
        return Err(anyhow!(
            "{}: model {model} runs in `incise run`, `preview`, `xr`, `render`, `soak` and `bench scene`; this command needs an Xpbd scene",
            scene_path.display()
        ));
    }
    let dir = scene_path.parent().unwrap_or(Path::new("."));
    let (raw, generated_skin) = raw_mesh(&scene.mesh, dir)?;
    let (mesh, mesh_report) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", scene_path.display()))?;
    let skin = match (&scene.skin, generated_skin) {
        (SkinSource::Auto, Some(surface)) => Skin::embed(&mesh, surface),
        (SkinSource::Auto | SkinSource::Boundary, _) => Skin::from_boundary(&mesh),
        (SkinSource::Obj { path, units }, _) => {
            let p = dir.join(path);
            let mut s = io::load_surface(&p)
                .with_context(|| format!("skin of {}", scene_path.display()))?;
            scale(&mut s.positions, units.scale());
            Skin::embed(&mesh, s)
        }
    };
    let (material, material_name) = super::scene_material(scene, scene_path)?;
    let mut params = scene.solver.clone();
    params.release_threshold = scene.cutting.as_ref().map(|c| c.von_mises_threshold);
    if let Some(t) = threads {
        params.threads = t;
    }
    let rest = mesh.rest_positions.clone();
    let mut solver =
        Solver::new(mesh, material, params).with_context(|| scene_path.display().to_string())?;
    let mut pinned = 0;
    for (i, sel) in scene.pins.iter().enumerate() {
        let nodes = sel
            .select(&rest)
            .with_context(|| format!("{}: pins[{i}]", scene_path.display()))?;
        pinned += nodes.len();
        solver.pin(&nodes);
    }
    let mut grabbed = 0;
    for (i, g) in scene.grabs.iter().enumerate() {
        let nodes = g
            .nodes
            .select(&rest)
            .with_context(|| format!("{}: grabs[{i}].nodes", scene_path.display()))?;
        grabbed += nodes.len();
        solver.add_grab(Grab {
            nodes,
            waypoints: g.path.clone(),
            speed: g.speed,
            start_time: g.start,
        });
    }
    // The implicit scheme's workspace is built at load, not in the first frame.
    solver
        .prepare()
        .with_context(|| format!("{}: solver.scheme", scene_path.display()))?;
    let tool = match (&scene.tool, &scene.stroke) {
        (None, None) if driver == ToolDriver::Hand => {
            let tool = super::hand_tool::default_tool()?;
            let contact = tool.contact_tool(solver.mesh().mean_edge_length());
            Some(SceneTool {
                tool,
                contact,
                stroke: None,
            })
        }
        (None, None) => None,
        (Some(_), None) => bail!(
            "{}: stroke: a scene with a tool needs a stroke (File(\"...\") or Incision(...))",
            scene_path.display()
        ),
        (None, Some(_)) => bail!(
            "{}: tool: a stroke needs a tool, e.g. tool: Some((file: \"tools/scalpel_10.ron\"))",
            scene_path.display()
        ),
        (Some(spec), Some(stroke)) => {
            let (tool, stroke) = super::tool::load(spec, stroke, scene_path)?;
            let mut contact = tool.contact_tool(solver.mesh().mean_edge_length());
            if spec.dull {
                contact = contact.dulled();
            }
            solver
                .set_tool(contact.clone(), stroke.pose_at(0.0))
                .with_context(|| format!("{}: tool", scene_path.display()))?;
            Some(SceneTool {
                tool,
                contact,
                stroke: Some(stroke),
            })
        }
    };
    Ok(BuiltScene {
        tool,
        solver,
        skin,
        material,
        material_name,
        mesh_report,
        pinned_nodes: pinned,
        grabbed_nodes: grabbed,
    })
}

/// The raw tet mesh (in metres) and the generator's skin, if any.
pub fn raw_mesh(source: &MeshSource, dir: &Path) -> Result<(RawMesh, Option<TriSurface>)> {
    Ok(match source {
        MeshSource::File { path, units } => {
            let mut raw = io::load_mesh(&dir.join(path))?;
            scale(&mut raw.positions, units.scale());
            (raw, None)
        }
        MeshSource::Generate(g) => match g {
            Generator::Plate => (generate::plate(), None),
            Generator::Chest => (generate::chest(), None),
            Generator::Intestine(p) => {
                let problems = p.problems();
                if !problems.is_empty() {
                    return Err(anyhow!(
                        "mesh: Generate(Intestine(..)): {}",
                        problems.join("; ")
                    ));
                }
                let (raw, skin) = generate::intestine(p);
                (raw, Some(skin))
            }
            Generator::Block { min, size, cells } => (generate::block(*min, *size, *cells), None),
            Generator::Beam {
                length,
                width,
                height,
                cells,
            } => (generate::beam(*length, *width, *height, *cells), None),
        },
    })
}

fn scale(points: &mut [glam::Vec3], s: f32) {
    if s != 1.0 {
        points.iter_mut().for_each(|p| *p *= s);
    }
}
