//! The XPBD method behind [`SimBody`] (PHYSICS.md §1): the Neo-Hookean solver on the
//! device the user chose ([`Body`]), its scalpel driven by the scene's stroke or a hand,
//! tets released where the von Mises stress passes the threshold.

use std::path::Path;

use anyhow::{Result, bail};
use glam::Vec3;
use incise_sim::Solver;
use incise_sim::contact::ToolPose;
use incise_sim::io::{VtuFrame, write_vtu};
use incise_sim::skin::Skin;
use incise_sim::xpbd::SolverError;

use super::interface::{
    Fault, OpenOptions, Quantity, SimBody, SolverParts, StepError, Surface, TetView, ToolInput,
};
use super::outcome::{Outcome, StateHash};
use super::rest_cut::RestCut;
use super::vertex_field::vertex_mean;
use super::xpbd_device::Body;
use crate::report::{FrameData, MaterialInfo, MeshInfo, Report, ToolInfo};
use crate::scene::Method;
use crate::scene::{BuiltScene, SceneTool, ToolDriver, build_scene_driven};

/// The heat map of an XPBD body: the tets' von Mises stress at their nodes.
const VON_MISES: Quantity = Quantity {
    name: "von Mises stress",
    unit: "Pa",
};

/// An XPBD body with its skin and, when the scene has one, its scalpel.
pub struct XpbdBody {
    /// The solver on its device.
    pub body: Body,
    /// The skin embedded in the tets.
    pub skin: Skin,
    /// The scalpel and the stroke that drives it in a scripted run.
    pub tool: Option<SceneTool>,
    /// Where the tool was put for the last frame.
    pose: Option<ToolPose>,
    /// Whether the tool is held without cutting (a hand's trigger up, a recorded stroke's
    /// lifted span): it pushes, dulled, as the headset's does.
    lifted: bool,
}

/// Open `scene` (from `path`) as an XPBD body with the run's report skeleton.
pub fn open(
    scene: &crate::scene::Scene,
    path: &Path,
    opts: &OpenOptions,
) -> Result<(XpbdBody, Report)> {
    if opts.haptic_rate.is_some() {
        bail!(
            "{}: --haptic-rate runs the mass-spring haptic loop; this scene's model is Xpbd",
            path.display()
        );
    }
    // A recorded stroke is a hand's: the scene gets the tool the preview gave it
    // (scene/hand_tool.rs), so the replay is the same physics.
    let driver = match opts.stroke {
        Some(_) => ToolDriver::Hand,
        None => ToolDriver::Scene,
    };
    let mut built = build_scene_driven(scene, path, opts.threads, driver)?;
    if let (Some(t), Some(file)) = (built.tool.as_mut(), &opts.stroke) {
        t.stroke = Some(incise_scalpel::load_stroke(file)?);
    }
    // The tool this run drives: one with a stroke.
    let tool = built.tool.take().filter(|t| t.stroke.is_some());
    let pose = tool
        .as_ref()
        .and_then(|t| t.stroke.as_ref())
        .map(|s| s.pose_at(0.0));
    if let (Some(t), Some(p)) = (&tool, pose) {
        built.solver.set_tool(t.contact.clone(), p)?;
    }
    let mut report = skeleton(scene, path, &built, tool.as_ref());
    let mut choice = None;
    let BuiltScene { solver, skin, .. } = built;
    let body = Body::place_on(solver, opts.device, opts.gpu.as_ref(), |m| {
        choice = Some(m.to_string())
    })?;
    if let Some(m) = choice.as_ref().filter(|_| !opts.quiet) {
        eprintln!("note: {m}");
    }
    report.device = body.device();
    report.device_choice = choice;
    report.threads = match body.solver().params().threads {
        0 => rayon::current_num_threads(),
        n => n,
    };
    Ok((
        XpbdBody {
            body,
            skin,
            tool,
            pose,
            lifted: false,
        },
        report,
    ))
}

/// The report's head for `built`: mesh, material, solver settings, tool.
fn skeleton(
    scene: &crate::scene::Scene,
    path: &Path,
    built: &BuiltScene,
    tool: Option<&SceneTool>,
) -> Report {
    let solver = &built.solver;
    let mesh = solver.mesh();
    let lame = solver.lame();
    let mut report = Report::begin(
        scene,
        path,
        ("xpbd", Method::Xpbd),
        MeshInfo {
            nodes: mesh.node_count(),
            tets: mesh.tet_count(),
            reoriented_tets: built.mesh_report.reoriented_tets,
            colors: solver.color_count(),
            skin_vertices: built.skin.surface.positions.len(),
            skin_triangles: built.skin.surface.triangles.len(),
            pinned_nodes: built.pinned_nodes,
            grabbed_nodes: built.grabbed_nodes,
            warnings: built.mesh_report.warnings.clone(),
        },
        solver.params().clone(),
    );
    report.material = Some(MaterialInfo {
        name: built.material_name.clone(),
        values: built.material,
        mu: lame.mu,
        lambda: lame.lambda,
    });
    report.tool = tool.map(tool_info);
    report
}

/// The scalpel for the report.
fn tool_info(t: &SceneTool) -> ToolInfo {
    ToolInfo {
        name: t.tool.name().to_string(),
        spheres: t.contact.spheres.len(),
        cutting_spheres: t.contact.spheres.iter().filter(|s| s.cutting).count(),
        sphere_radius: t.contact.spheres.first().map_or(0.0, |s| s.radius),
        boxes: t.contact.boxes.len(),
        friction: t.contact.friction,
        stroke_duration: t.stroke.as_ref().map_or(0.0, |s| s.duration()),
    }
}

impl XpbdBody {
    /// Where `tool` puts the scalpel at the end of the next frame, and whether it holds
    /// it there without cutting: a hand's trigger up, or the stroke's lifted span (a
    /// recorded hand's).
    fn next_pose(&self, tool: &ToolInput) -> Option<(ToolPose, bool)> {
        match tool {
            ToolInput::Hand { pose, engaged } => Some((*pose, !engaged)),
            ToolInput::Script => {
                let stroke = self.tool.as_ref()?.stroke.as_ref()?;
                let t = (self.body.solver().frame() + 1) as f64 * self.frame_dt();
                Some((stroke.pose_at(t), stroke.lifted_at(t)))
            }
        }
    }

    /// Put the scalpel at `pose` for the next frame, dulled while `lifted` (the tool is
    /// set anew, as the headset's `XrBody::drive_tool` does, when that changes).
    fn place_tool(&mut self, pose: ToolPose, lifted: bool) -> Result<(), SolverError> {
        self.pose = Some(pose);
        match &self.tool {
            Some(t) if lifted != self.lifted => {
                self.lifted = lifted;
                let contact = match lifted {
                    true => t.contact.dulled(),
                    false => t.contact.clone(),
                };
                self.body.set_tool(contact, pose)
            }
            _ => {
                self.body.move_tool(pose);
                Ok(())
            }
        }
    }
}

impl SimBody for XpbdBody {
    fn method(&self) -> Method {
        Method::Xpbd
    }

    fn frame_dt(&self) -> f64 {
        self.body.solver().params().frame_dt as f64
    }

    fn time(&self) -> f64 {
        self.body.solver().time()
    }

    fn step(&mut self, tool: &ToolInput) -> Result<FrameData, StepError> {
        if let Some((pose, lifted)) = self.next_pose(tool) {
            self.place_tool(pose, lifted)
                .map_err(|e| StepError::Failed(e.to_string()))?;
        }
        match self.body.step_frame() {
            Ok(stats) => Ok(FrameData::Xpbd(stats)),
            Err(SolverError::Device(msg)) => Err(StepError::DeviceLost(msg)),
            Err(e) => Err(StepError::Failed(e.to_string())),
        }
    }

    fn tool_pose(&self) -> Option<ToolPose> {
        self.pose
    }

    fn scalpel_pose(&self) -> Option<ToolPose> {
        self.pose
    }

    fn tool_force(&self) -> Option<Vec3> {
        self.tool.as_ref()?;
        Some(self.body.solver().tool_force())
    }

    fn surface(&self) -> Surface {
        let s = self.body.solver();
        let (mesh, cut) = (s.mesh(), s.cut());
        let mut surface = Surface {
            positions: s.positions().to_vec(),
            scalar: vertex_mean(
                mesh.node_count(),
                &mesh.tets,
                |t| cut.is_live(t),
                s.von_mises(),
            ),
            quantity: Some(VON_MISES),
            ..Surface::default()
        };
        for &(t, f) in cut.visible_faces() {
            let tri = mesh.face_nodes(t as usize, f as usize);
            match mesh.face_neighbors[t as usize][f as usize] {
                incise_sim::mesh::NO_NEIGHBOR => surface.triangles.push(tri),
                _ => surface.cut_triangles.push(tri),
            }
        }
        surface
    }

    fn tet_view(&self) -> TetView {
        let s = self.body.solver();
        TetView {
            positions: s.positions().to_vec(),
            tets: s.mesh().tets.clone(),
            per_tet: s.von_mises().to_vec(),
            quantity: Some(VON_MISES),
        }
    }

    fn write_vtu(&self, path: &Path) -> Result<()> {
        write_solver_vtu(self.body.solver(), path)
    }

    fn progress_line(&self, frame: &FrameData) -> String {
        match frame {
            FrameData::Xpbd(s) => format!(
                "max σvM {:.0} Pa, released {}, tool {:.2} N",
                s.max_von_mises,
                s.released_total,
                s.tool_force.length()
            ),
            FrameData::Edges(_) => String::new(),
        }
    }

    fn device(&self) -> String {
        self.body.device()
    }

    fn gpu_frame_ms(&self) -> Option<f64> {
        self.body.gpu_frame_ms()
    }

    fn into_cpu(self: Box<Self>) -> Box<dyn SimBody> {
        let XpbdBody {
            body,
            skin,
            tool,
            pose,
            lifted,
        } = *self;
        Box::new(XpbdBody {
            body: body.into_cpu(),
            skin,
            tool,
            pose,
            lifted,
        })
    }

    fn outcome(&self) -> Option<Outcome> {
        let released = released_tets(self.body.solver());
        Some(Outcome {
            summary: format!("{} tets released", released.len()),
            hash: StateHash::new()
                .ints(released.iter().map(|&t| u64::from(t)))
                .finish(),
            released: Some(released.len()),
        })
    }

    fn rest_cut(&self) -> Option<RestCut> {
        Some(RestCut::released_of(self.body.solver()))
    }

    fn inject(&mut self, fault: Fault) -> Result<()> {
        match fault {
            Fault::Nan => self.body.inject_nan(),
            Fault::DeviceLoss => self.body.inject_device_loss(),
        }
        Ok(())
    }

    fn finish(&mut self, report: &mut Report) -> Result<Option<String>> {
        report.released_tets = released_tets(self.body.solver());
        Ok(None)
    }

    fn solver_parts(&self) -> Option<SolverParts<'_>> {
        Some(SolverParts {
            body: &self.body,
            skin: &self.skin,
            tool: self.tool.as_ref().map(|t| &t.tool),
        })
    }
}

/// The tets `solver` has released, in index order.
pub fn released_tets(solver: &Solver) -> Vec<u32> {
    let cut = solver.cut();
    (0..solver.mesh().tet_count() as u32)
        .filter(|&t| !cut.is_live(t as usize))
        .collect()
}

/// Write `solver`'s state as a `.vtu` at `path`: per tet von Mises stress and released,
/// per node velocity.
pub fn write_solver_vtu(solver: &Solver, path: &Path) -> Result<()> {
    let released: Vec<f32> = solver
        .cut()
        .live()
        .iter()
        .map(|&l| if l { 0.0 } else { 1.0 })
        .collect();
    let frame = VtuFrame {
        positions: solver.positions(),
        tets: &solver.mesh().tets,
        cell_scalars: vec![("von_mises", solver.von_mises()), ("released", &released)],
        point_vectors: vec![("velocity", solver.velocities())],
        point_scalars: vec![],
    };
    Ok(write_vtu(path, &frame)?)
}
