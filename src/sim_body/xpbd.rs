//! The XPBD method behind [`SimBody`] (PHYSICS.md §1): the Neo-Hookean solver on the
//! device the user chose ([`Body`]), its scalpel driven by the scene's stroke or a hand,
//! tets released where the von Mises stress passes the threshold.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use anyhow::{Result, bail};
use glam::{Quat, Vec3};
use incise_sim::contact::{CutZone, ToolPose};
use incise_sim::gpu::GpuContext;
use incise_sim::implicit::Scheme;
use incise_sim::io::{VtuFrame, write_vtu};
use incise_sim::skin::Skin;
use incise_sim::xpbd::SolverError;
use incise_sim::{Material, Solver};

use super::body_view::{BodyView, CutShape, CutView, Quantity, Substeps, TetView};
use super::interface::{Fault, OpenOptions, SimBody, SolverParts, StepError, Surface, ToolInput};
use super::outcome::{Outcome, StateHash};
use super::rest_cut::RestCut;
use super::tunables::Tunables;
use super::vertex_field::vertex_mean;
use super::xpbd_device::{Body, DeviceChoice};
use crate::report::{FrameData, MaterialInfo, MeshInfo, Report, ToolInfo};
use crate::scene::Method;
use crate::scene::hand_tool::edge_zone;
use crate::scene::{BuiltScene, SceneTool, ToolDriver, build_scene_driven};

/// The heat map of an XPBD body: the tets' von Mises stress at their nodes.
pub const VON_MISES: Quantity = Quantity {
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
    /// Whether the tool was moved by a hand or a stroke in the last frame; a hand that
    /// takes a waiting tool puts it where it holds it at once (no sweep from where it
    /// waited).
    held: bool,
    /// The scene's own cut zone (the edge zone of a retune derives from it).
    scene_zone: CutZone,
    /// The mesh, skin and pins every drawn frame shares, made when a frame is first drawn
    /// (a run that draws none does not copy the mesh).
    shape: OnceLock<Arc<CutShape>>,
    /// The material, the scene's substeps and the fewest stable ones (for a retune; the
    /// fewest found when a pacer first asks).
    material: Material,
    nominal: u32,
    fewest: OnceLock<u32>,
    /// The GPU context the body was put on, to put a retuned solver on.
    gpu: Option<GpuContext>,
}

/// Where a hand's tool waits until the hand takes it: 1 m above the organ.
fn parked(solver: &Solver) -> ToolPose {
    let (lo, hi) = solver.mesh().rest_bounds();
    let c = (lo + hi) * 0.5;
    ToolPose {
        position: Vec3::new(c.x, c.y, hi.z + 1.0),
        rotation: Quat::IDENTITY,
    }
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
    let driver = match opts.stroke.is_some() || opts.hand {
        true => ToolDriver::Hand,
        false => ToolDriver::Scene,
    };
    let on_scheme;
    let scene = match opts.scheme {
        Some(scheme) => {
            let mut s = scene.clone();
            s.solver.scheme = scheme;
            on_scheme = s;
            &on_scheme
        }
        None => scene,
    };
    let mut built = build_scene_driven(scene, path, opts.threads, driver)?;
    if let Some(t) = built.tool.as_mut() {
        match &opts.stroke {
            Some(file) => t.stroke = Some(incise_scalpel::load_stroke(file)?),
            None if opts.hand && !opts.script_until_taken => t.stroke = None,
            None => {}
        }
    }
    // The tool this run drives: one with a stroke, or a hand's.
    let tool = built
        .tool
        .take()
        .filter(|t| t.stroke.is_some() || opts.hand);
    let pose = tool.as_ref().map(|t| match &t.stroke {
        Some(s) => s.pose_at(0.0),
        None => parked(&built.solver),
    });
    // Dulled while it waits for a hand, or where a recorded stroke starts lifted.
    let waiting = tool.as_ref().is_some_and(|t| t.stroke.is_none());
    let lifted = tool.as_ref().is_some_and(|t| match &t.stroke {
        Some(s) => s.lifted_at(0.0),
        None => true,
    });
    if let (Some(t), Some(p)) = (&tool, pose) {
        let contact = match lifted {
            true => t.contact.dulled(),
            false => t.contact.clone(),
        };
        built.solver.set_tool(contact, p)?;
    }
    let mut report = skeleton(scene, path, &built, tool.as_ref());
    let mut choice = None;
    let BuiltScene {
        solver,
        skin,
        material,
        ..
    } = built;
    let (nominal, scene_zone) = (solver.params().substeps, solver.params().cut_zone);
    let body = Body::place_on(solver, opts.device, opts.gpu.as_ref(), |m| {
        choice = Some(m.to_string())
    })?;
    if let Some(m) = choice.as_ref().filter(|_| !opts.quiet) {
        eprintln!("note: {m}");
    }
    report.device = body.device();
    report.device_choice = choice;
    report.threads = body.solver().threads();
    Ok((
        XpbdBody {
            body,
            skin,
            tool,
            pose,
            lifted,
            held: !waiting,
            scene_zone,
            shape: OnceLock::new(),
            material,
            nominal,
            fewest: OnceLock::new(),
            gpu: opts.gpu.clone(),
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
    /// Go on with `material` and `params` on `device` ([`Solver::retuned`]: motion, cut,
    /// grabs and tool carried over); refused settings leave the body as it was.
    fn rebuild(
        &mut self,
        material: Material,
        params: incise_sim::SolverParams,
        device: DeviceChoice,
    ) -> Result<()> {
        let s = self.body.solver().retuned(material, params)?;
        self.body = Body::place_on(s, device, self.gpu.as_ref(), |_| {})?;
        self.material = material;
        Ok(())
    }

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

    /// Put the scalpel at `pose` for the next frame, dulled while `lifted`: the tool is
    /// set anew (no sweep) when that changes or when a hand takes a waiting tool; else it
    /// moves there over the frame.
    fn place_tool(&mut self, pose: ToolPose, lifted: bool) -> Result<(), SolverError> {
        self.pose = Some(pose);
        let taken = !std::mem::replace(&mut self.held, true);
        match &self.tool {
            Some(t) if lifted != self.lifted || taken => {
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
        match self.next_pose(tool) {
            Some((pose, lifted)) => self
                .place_tool(pose, lifted)
                .map_err(|e| StepError::Failed(e.to_string()))?,
            // The tool stays where it was; a hand that takes it again puts it at once.
            None => self.held = false,
        }
        match self.body.step_frame() {
            Ok(stats) => Ok(FrameData::Xpbd(stats)),
            Err(SolverError::Device(msg)) => Err(StepError::DeviceLost(msg)),
            Err(e) => Err(StepError::Failed(e.to_string())),
        }
    }

    fn prepare_next_frame(&mut self) {
        self.body.prepare_frame();
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
        let b = *self;
        Box::new(XpbdBody {
            body: b.body.into_cpu(),
            gpu: None,
            ..b
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

    fn view(&self, previous: Option<&CutView>) -> BodyView {
        let s = self.body.solver();
        let shape = self.shape.get_or_init(|| {
            Arc::new(CutShape {
                mesh: s.mesh().clone(),
                skin: self.skin.clone(),
                pinned: s.pinned_nodes(),
            })
        });
        let released = s.cut().released_count();
        // A frame of this body (the same shape: a reset makes a new body) with as many tets
        // released shares its cut.
        let shared = match previous {
            Some(p) if Arc::ptr_eq(&p.shape, shape) => {
                (p.cut.released_count() == released).then(|| p.cut.clone())
            }
            _ => None,
        };
        BodyView::Cut(CutView {
            shape: shape.clone(),
            positions: s.positions().to_vec(),
            cut: shared.unwrap_or_else(|| Arc::new(s.cut().clone())),
            von_mises: s.von_mises().to_vec(),
            stress_max: stress_scale(s),
        })
    }

    fn substeps(&self) -> Option<Substeps> {
        // The implicit scheme steps a frame its own way: it has no substeps to cut.
        if self.body.solver().params().scheme != Scheme::Xpbd {
            return None;
        }
        Some(Substeps {
            now: self.body.solver().params().substeps,
            nominal: self.nominal,
            fewest: *self.fewest.get_or_init(|| {
                let s = self.body.solver();
                s.fewest_stable_substeps().clamp(1, self.nominal)
            }),
        })
    }

    fn set_substeps(&mut self, n: u32) -> Result<()> {
        if self.substeps().is_none() {
            bail!("the implicit scheme has no substeps to set to {n}");
        }
        let old = self.body.solver();
        if n == old.params().substeps {
            return Ok(());
        }
        let mut params = old.params().clone();
        params.substeps = n;
        let device = match &self.body {
            Body::Cpu(_) => DeviceChoice::Cpu,
            Body::Gpu(_) => DeviceChoice::Gpu,
        };
        self.rebuild(self.material, params, device)
    }

    fn script_holds_tool(&self) -> bool {
        self.tool.as_ref().is_some_and(|t| t.stroke.is_some())
    }

    fn hold_tool(&mut self, pose: ToolPose, engaged: bool) -> Result<()> {
        self.held = false;
        Ok(self.place_tool(pose, !engaged)?)
    }

    fn tunables(&self) -> Option<Tunables> {
        let p = self.body.solver().params();
        Some(Tunables {
            youngs_modulus: self.material.youngs_modulus,
            poisson_ratio: self.material.poisson_ratio,
            damping: p.damping,
            cut_threshold: p.release_threshold,
            cut_zone: p.cut_zone,
            edge_zone: match self.scene_zone {
                CutZone::Anywhere => edge_zone(self.body.solver().mesh().mean_edge_length()),
                own => own,
            },
            substeps: p.substeps,
            implicit: p.scheme != Scheme::Xpbd,
            newton: p.scheme.newton_or_default(),
            poisson_range: p.poisson_range(),
        })
    }

    fn retune(&mut self, t: Tunables, device: DeviceChoice) -> Result<()> {
        let material = Material {
            youngs_modulus: t.youngs_modulus,
            poisson_ratio: t.poisson_ratio,
            ..self.material
        };
        let mut params = self.body.solver().params().clone();
        params.damping = t.damping;
        params.release_threshold = t.cut_threshold;
        params.cut_zone = t.cut_zone;
        params.substeps = t.substeps;
        params.scheme = match t.implicit {
            true => Scheme::Newton(t.newton),
            false => Scheme::Xpbd,
        };
        self.rebuild(material, params, device)
    }

    fn solver_parts(&self) -> Option<SolverParts<'_>> {
        Some(SolverParts {
            body: &self.body,
            skin: &self.skin,
            tool: self.tool.as_ref().map(|t| &t.tool),
        })
    }
}

/// Full scale of `solver`'s stress heat map: its release threshold, else the largest
/// stress now (at least 1 Pa).
pub fn stress_scale(solver: &Solver) -> f32 {
    solver
        .params()
        .release_threshold
        .unwrap_or_else(|| solver.von_mises().iter().copied().fold(1.0, f32::max))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `config/plate_cut.ron` opened for a hand (the headset's controller).
    fn hand_plate() -> XpbdBody {
        hand_body("config/plate_cut.ron")
    }

    /// The scene at `file` (from the repository root) opened for a hand.
    fn hand_body(file: &str) -> XpbdBody {
        hand_body_with(file, |_| {})
    }

    /// The scene at `file`, changed by `edit`, opened for a hand.
    fn hand_body_with(file: &str, edit: impl FnOnce(&mut crate::scene::Scene)) -> XpbdBody {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let mut scene = crate::scene::load_scene(&path).unwrap();
        edit(&mut scene);
        let opts = OpenOptions {
            device: DeviceChoice::Cpu,
            hand: true,
            quiet: true,
            ..OpenOptions::default()
        };
        open(&scene, &path, &opts).unwrap().0
    }

    #[test]
    fn a_hands_scalpel_waits_then_goes_where_the_hand_holds_it() {
        let mut b = hand_plate();
        assert!(!b.script_holds_tool(), "the scene's stroke is not played");
        let parked = b.tool_pose().unwrap();
        let (_, hi) = b.body.solver().mesh().rest_bounds();
        assert!(parked.position.z > hi.z + 0.5, "{parked:?}");
        // The script moves nothing: the blade waits.
        b.step(&ToolInput::Script).unwrap();
        assert_eq!(b.body.solver().tool().unwrap().to, parked);
        // The hand takes it on the plate, trigger up: it is put there at once (its motion
        // over the next frame starts there), not swept down from where it waited.
        let at = |x: f32| ToolPose {
            position: Vec3::new(x, 0.02, 0.021),
            rotation: Quat::IDENTITY,
        };
        let motion = |b: &XpbdBody| {
            let m = b.body.solver().tool().unwrap();
            (m.from, m.to)
        };
        b.place_tool(at(0.04), true).unwrap();
        assert_eq!(motion(&b), (at(0.04), at(0.04)));
        // Held, it moves over the frame.
        b.place_tool(at(0.045), true).unwrap();
        assert_eq!(motion(&b), (at(0.04), at(0.045)));
        // Let go (untracked: the script's turn, which moves nothing) and taken again
        // elsewhere: put there at once again.
        b.step(&ToolInput::Script).unwrap();
        b.place_tool(at(0.02), true).unwrap();
        assert_eq!(motion(&b), (at(0.02), at(0.02)));
    }

    #[test]
    fn fewer_substeps_keep_the_state_and_the_tool() {
        // XPBD's substeps: the shipped scene names no scheme and runs the implicit one.
        let mut b = hand_body_with("config/plate_cut.ron", |s| {
            s.solver.scheme = incise_sim::implicit::Scheme::Xpbd
        });
        let s = b.substeps().unwrap();
        assert!(s.fewest >= 1 && s.fewest < s.nominal, "{s:?}");
        let pose = ToolPose {
            position: Vec3::new(0.04, 0.02, 0.021),
            rotation: Quat::IDENTITY,
        };
        for _ in 0..3 {
            b.step(&ToolInput::Hand {
                pose,
                engaged: true,
            })
            .unwrap();
        }
        let Body::Cpu(solver) = &mut b.body else {
            panic!("--device cpu gave a GPU body")
        };
        solver.release(&[100, 2000, 5000]);
        let before = b.body.solver().positions().to_vec();
        let moving = b.body.solver().velocities().to_vec();
        let released = released_tets(b.body.solver());
        let time = b.time();
        b.set_substeps(s.fewest).unwrap();
        assert_eq!(b.substeps().unwrap().now, s.fewest);
        let after = b.body.solver();
        assert_eq!(after.positions(), &before[..]);
        assert_eq!(after.velocities(), &moving[..]);
        assert_eq!(released_tets(after), released, "the cut kept");
        assert_eq!(b.time(), time, "the clock goes on");
        assert_eq!(after.tool().unwrap().to, pose, "the scalpel stays attached");
        assert!(b.set_substeps(s.nominal).is_ok());
    }

    /// The implicit scheme has no substeps for a pacer to cut (a retune would rebuild its
    /// multigrid workspace for nothing).
    #[test]
    fn a_newton_body_has_no_substeps_to_cut() {
        let mut b = hand_body("config/bowel_cantilever.ron");
        assert_eq!(b.substeps(), None);
        assert!(b.set_substeps(3).is_err());
    }

    /// How far `a`'s furthest node moved from rest, and how far apart `a` and `b` are at
    /// their furthest node, m.
    fn moved_and_apart(a: &Solver, b: &Solver) -> (f32, f32) {
        let largest = |d: &mut dyn Iterator<Item = f32>| d.fold(0.0f32, f32::max);
        let rest = &a.mesh().rest_positions;
        let (x, y) = (a.positions(), b.positions());
        let moved = largest(&mut x.iter().zip(rest).map(|(p, r)| (*p - *r).length()));
        let apart = largest(&mut x.iter().zip(y).map(|(p, q)| (*p - *q).length()));
        (moved, apart)
    }

    /// A setting changed during a pull (the preview's slider): the body goes on from
    /// where the grab had taken the tissue, as the same frames would without the change,
    /// neither restarting the grab's path nor dropping it.
    #[test]
    fn a_setting_changed_mid_pull_keeps_the_grab_going() {
        let (mut same, mut tuned) = (
            hand_body("config/plate_stretch.ron"),
            hand_body("config/plate_stretch.ron"),
        );
        for b in [&mut same, &mut tuned] {
            for _ in 0..20 {
                b.step(&ToolInput::Script).unwrap();
            }
        }
        let t = tuned.tunables().unwrap();
        let damped = Tunables {
            damping: t.damping * 1.001,
            ..t
        };
        tuned.retune(damped, DeviceChoice::Cpu).unwrap();
        assert_eq!(tuned.tunables().unwrap(), damped);
        assert_eq!(tuned.body.solver().frame(), 20, "the frame count goes on");
        for b in [&mut same, &mut tuned] {
            for _ in 0..20 {
                b.step(&ToolInput::Script).unwrap();
            }
        }
        let (moved, apart) = moved_and_apart(same.body.solver(), tuned.body.solver());
        assert!(moved > 1e-3, "the grab pulls the plate: {moved} m");
        assert!(
            apart < 0.01 * moved,
            "a 0.1 % damping change moved the body {apart} m of {moved}"
        );
    }

    /// The panel's scheme switch during a pull: the body goes on on the implicit scheme
    /// from where XPBD had taken it (frame count, grab and motion carried over), lands
    /// where XPBD goes (the plate's pull is converged on both), and switches back.
    #[test]
    fn the_scheme_switches_mid_pull_and_back() {
        let (mut xpbd, mut switched) = (
            hand_body("config/plate_stretch.ron"),
            hand_body("config/plate_stretch.ron"),
        );
        let run = |b: &mut XpbdBody, frames: usize| {
            for _ in 0..frames {
                b.step(&ToolInput::Script).unwrap();
            }
        };
        run(&mut xpbd, 20);
        run(&mut switched, 20);
        let own = switched.tunables().unwrap();
        assert!(!own.implicit, "plate_stretch runs XPBD");
        let implicit = Tunables {
            implicit: true,
            ..own
        };
        switched.retune(implicit, DeviceChoice::Cpu).unwrap();
        assert!(matches!(
            switched.body.solver().params().scheme,
            Scheme::Newton(_)
        ));
        assert_eq!(switched.substeps(), None, "no substeps to pace");
        assert_eq!(
            switched.body.solver().frame(),
            20,
            "the frame count goes on"
        );
        run(&mut xpbd, 20);
        run(&mut switched, 20);
        let (moved, apart) = moved_and_apart(xpbd.body.solver(), switched.body.solver());
        assert!(moved > 1e-3, "the grab pulls the plate: {moved} m");
        assert!(
            apart < 0.05 * moved,
            "on the implicit scheme the plate is {apart} m from XPBD's of {moved}"
        );
        switched.retune(own, DeviceChoice::Cpu).unwrap();
        assert_eq!(switched.body.solver().params().scheme, Scheme::Xpbd);
        assert_eq!(switched.tunables().unwrap(), own);
        run(&mut switched, 1);
    }

    /// "Only along the blade's edge" on a tearing scene: with the edge zone the grab
    /// stretches the plate without releasing a tet (the blade waits away from it); with
    /// the scene's own zone again, the same body tears where the stress passes the
    /// threshold, as `incise run` does.
    #[test]
    fn the_edge_zone_stops_and_restores_tearing() {
        let mut b = hand_body("config/plate_stretch.ron");
        let own = b.tunables().unwrap();
        assert_eq!(own.cut_zone, CutZone::Anywhere, "the scene's own zone");
        let edge = Tunables {
            cut_zone: own.edge_zone,
            ..own
        };
        b.retune(edge, DeviceChoice::Cpu).unwrap();
        assert_eq!(b.body.solver().params().cut_zone, own.edge_zone);
        for _ in 0..150 {
            b.step(&ToolInput::Script).unwrap();
        }
        let released = |b: &XpbdBody| b.body.solver().cut().released_count();
        assert_eq!(released(&b), 0, "the edge zone tore the plate");
        b.retune(own, DeviceChoice::Cpu).unwrap();
        for _ in 0..5 {
            b.step(&ToolInput::Script).unwrap();
        }
        assert!(
            released(&b) > 0,
            "back to its own zone, the stretched plate tears"
        );
    }

    /// Unusable settings are refused and leave the body as it was.
    #[test]
    fn refused_settings_leave_the_body_as_it_was() {
        let mut b = hand_plate();
        let t = b.tunables().unwrap();
        let broken = Tunables {
            poisson_ratio: 0.7,
            ..t
        };
        assert!(b.retune(broken, DeviceChoice::Cpu).is_err());
        assert_eq!(b.tunables().unwrap(), t);
    }

    /// A recording's first pose (the preview's): the hand holds the tool there at frame 0
    /// without a step, so the first frame sweeps it from there, as the replay of the
    /// recorded stroke does from its first key.
    #[test]
    fn a_held_tool_starts_the_next_frame_where_it_was_put() {
        let mut b = hand_plate();
        let at = |x: f32| ToolPose {
            position: Vec3::new(x, 0.02, 0.03),
            rotation: Quat::IDENTITY,
        };
        b.hold_tool(at(0.04), true).unwrap();
        let m = b.body.solver().tool().unwrap();
        assert_eq!((m.from, m.to), (at(0.04), at(0.04)));
        // The next frame's hand pose, engaged as held: the tool moves over the frame.
        b.place_tool(at(0.045), false).unwrap();
        let m = b.body.solver().tool().unwrap();
        assert_eq!(
            (m.from, m.to),
            (at(0.04), at(0.045)),
            "swept from the held pose"
        );
    }
}
