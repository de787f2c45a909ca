//! The simulated organ in the XR mode: the scene's solver with the scalpel attached
//! (sharp while the trigger is held, dull otherwise), its substeps changeable by the
//! pacer, and a reset to the scene's rest state.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use glam::{Quat, Vec3};
use incise_sim::contact::{ContactTool, ToolPose};
use incise_sim::skin::Skin;
use incise_sim::xpbd::FrameStats;
use incise_sim::{Material, Solver};
use incise_xr::RenderDevice;
#[cfg(test)]
use incise_xr::frame::pinned_nodes;

use crate::pictures::screenshots::place_on;
use crate::scene::{BuiltScene, Scene, build_scene, load_scene};
use crate::sim_body::{Body, DeviceChoice};

/// A bounding box: its min and max corners (sim world, m).
pub type CutBox = ([f32; 3], [f32; 3]);

/// The scalpel used when the scene names none, relative to the scene file.
pub const DEFAULT_TOOL: &str = "tools/scalpel_10.ron";

/// The organ, its scalpel and how to rebuild them.
pub struct XrBody {
    /// The solver on its device.
    pub body: Body,
    scene: Scene,
    path: PathBuf,
    device: DeviceChoice,
    dev: RenderDevice,
    material: Material,
    sharp: ContactTool,
    tool: incise_scalpel::Tool,
    engaged: bool,
    tracked: bool,
    pose: ToolPose,
    nominal: u32,
    min_substeps: u32,
}

/// The contact tool of `scene` (its own scalpel, else [`DEFAULT_TOOL`]) for `solver`.
fn scalpel(
    scene: &Scene,
    path: &Path,
    solver: &Solver,
) -> Result<(incise_scalpel::Tool, ContactTool)> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let (file, dull) = match &scene.tool {
        Some(t) => (dir.join(&t.file), t.dull),
        None => (dir.join(DEFAULT_TOOL), false),
    };
    let tool = incise_scalpel::load_tool(&file)
        .with_context(|| format!("{}: the XR scalpel", path.display()))?;
    let contact = tool.contact_tool(solver.mesh().mean_edge_length());
    Ok((tool, if dull { contact.dulled() } else { contact }))
}

/// Where the scalpel waits until the controller is tracked: 1 m above the organ.
fn parked(solver: &Solver) -> ToolPose {
    let (lo, hi) = solver.mesh().rest_bounds();
    let c = (lo + hi) * 0.5;
    ToolPose {
        position: Vec3::new(c.x, c.y, hi.z + 1.0),
        rotation: Quat::IDENTITY,
    }
}

impl XrBody {
    /// Load the scene at `path` for the XR mode; the body runs on `device` (a GPU body on
    /// `dev`). Returns the body and the skin to render.
    pub fn load(path: &Path, device: DeviceChoice, dev: &RenderDevice) -> Result<(XrBody, Skin)> {
        let mut scene = load_scene(path)?;
        // The controller drives the scalpel; the scene's own stroke is not used.
        let own_tool = scene.tool.take();
        scene.stroke = None;
        let BuiltScene {
            mut solver,
            skin,
            material,
            ..
        } = build_scene(&scene, path, None)?;
        scene.tool = own_tool;
        let (tool, sharp) = scalpel(&scene, path, &solver)?;
        let pose = parked(&solver);
        solver.set_tool(sharp.dulled(), pose)?;
        let nominal = solver.params().substeps;
        let min_substeps = solver.fewest_stable_substeps().clamp(1, nominal);
        let body = place_on(solver, device, dev)?;
        Ok((
            XrBody {
                body,
                scene,
                path: path.to_path_buf(),
                device,
                dev: dev.clone(),
                material,
                sharp,
                tool,
                engaged: false,
                tracked: false,
                pose,
                nominal,
                min_substeps,
            },
            skin,
        ))
    }

    /// The solver (or the GPU solver's host mirror).
    pub fn solver(&self) -> &Solver {
        self.body.solver()
    }

    /// The scalpel model (for scripted incisions).
    pub fn scalpel(&self) -> &incise_scalpel::Tool {
        &self.tool
    }

    /// The scene's substeps.
    pub fn nominal_substeps(&self) -> u32 {
        self.nominal
    }

    /// The fewest stable substeps.
    pub fn min_substeps(&self) -> u32 {
        self.min_substeps
    }

    /// The scene file.
    pub fn scene_path(&self) -> &Path {
        &self.path
    }

    /// The released tets, and the bounding box (min, max corners, sim world, m) of their
    /// rest centroids: how much was cut and where.
    pub fn cut_extent(&self) -> (usize, Option<CutBox>) {
        let solver = self.solver();
        let mesh = solver.mesh();
        let centroids: Vec<Vec3> = (0..mesh.tet_count())
            .filter(|&i| !solver.cut().is_live(i))
            .map(|i| {
                mesh.tets[i]
                    .iter()
                    .map(|&n| mesh.rest_positions[n as usize])
                    .sum::<Vec3>()
                    * 0.25
            })
            .collect();
        let bounds = centroids
            .iter()
            .fold(None, |b: Option<(Vec3, Vec3)>, &c| {
                let (lo, hi) = b.unwrap_or((c, c));
                Some((lo.min(c), hi.max(c)))
            })
            .map(|(lo, hi)| (lo.to_array(), hi.to_array()));
        (centroids.len(), bounds)
    }

    /// The scalpel's last pose, and whether the controller is tracked.
    pub fn tool(&self) -> (ToolPose, bool) {
        (self.pose, self.tracked)
    }

    fn contact(&self) -> ContactTool {
        if self.engaged {
            self.sharp.clone()
        } else {
            self.sharp.dulled()
        }
    }

    fn set_tool(&mut self) -> Result<()> {
        let (c, p) = (self.contact(), self.pose);
        match &mut self.body {
            Body::Cpu(s) => s.set_tool(c, p)?,
            Body::Gpu(g) => g.set_tool(c, p)?,
        }
        Ok(())
    }

    /// Drive the scalpel for the next simulation frame: to `pose` (sim world) while the
    /// controller is tracked, cutting only while `engaged`. When tracking starts the tool
    /// is placed there at once (no sweep from where it waited); untracked, it stays.
    pub fn drive_tool(&mut self, pose: Option<ToolPose>, engaged: bool) -> Result<()> {
        let Some(pose) = pose else {
            self.tracked = false;
            return Ok(());
        };
        let start = !self.tracked;
        self.tracked = true;
        self.pose = pose;
        if start || engaged != self.engaged {
            self.engaged = engaged;
            self.set_tool()
        } else {
            self.body.move_tool(pose);
            Ok(())
        }
    }

    /// Step one simulation frame.
    pub fn step(&mut self) -> Result<FrameStats> {
        Ok(self.body.step_frame()?)
    }

    /// Run `substeps` per frame from now on: the solver continues with the same state
    /// (positions, velocities, released tets, pins, grabs, tool: [`Solver::retuned`]).
    pub fn set_substeps(&mut self, substeps: u32) -> Result<()> {
        let old = self.body.solver();
        if substeps == old.params().substeps {
            return Ok(());
        }
        let mut params = old.params().clone();
        params.substeps = substeps;
        let s = old
            .retuned(self.material, params)
            .with_context(|| format!("{}: {substeps} substeps", self.path.display()))?;
        self.body = place_on(s, self.device, &self.dev)?;
        Ok(())
    }

    /// Back to the scene's rest state (A button); the scalpel waits until tracked.
    pub fn reset(&mut self) -> Result<()> {
        let BuiltScene { mut solver, .. } =
            build_scene(&self.scene_without_stroke(), &self.path, None)?;
        self.pose = parked(&solver);
        self.tracked = false;
        self.engaged = false;
        solver.set_tool(self.sharp.dulled(), self.pose)?;
        self.body = place_on(solver, self.device, &self.dev)?;
        Ok(())
    }

    fn scene_without_stroke(&self) -> Scene {
        Scene {
            tool: None,
            stroke: None,
            ..self.scene.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fewer_substeps_keep_state_and_tool_and_reset_goes_back_to_rest() {
        // Where the GPU is required (crates/test-gate) a missing adapter fails the test.
        let gate = incise_test_gate::Need::Gpu;
        let Some(dev) = incise_test_gate::or_skip(gate, RenderDevice::headless()) else {
            return;
        };
        let (mut xr, _) =
            XrBody::load(Path::new("config/plate_cut.ron"), DeviceChoice::Cpu, &dev).unwrap();
        let nominal = xr.nominal_substeps();
        let min = xr.min_substeps();
        assert!(
            min >= 1 && min < nominal,
            "plate_cut is stable below its {nominal} substeps: {min}"
        );
        // Blade resting on the top, engaged, and a few frames of sag under gravity.
        let pose = ToolPose {
            position: Vec3::new(0.04, 0.02, 0.021),
            rotation: Quat::IDENTITY,
        };
        for _ in 0..3 {
            xr.drive_tool(Some(pose), true).unwrap();
            xr.step().unwrap();
        }
        // A cut so far: three tets released by hand.
        let Body::Cpu(solver) = &mut xr.body else {
            panic!("--device cpu gave a GPU body")
        };
        solver.release(&[100, 2000, 5000]);
        let cut = released_tets(xr.solver());
        assert!(cut.len() >= 3, "{cut:?}");
        let before = xr.solver().positions().to_vec();
        let moving = xr.solver().velocities().to_vec();
        assert!(
            moving.iter().any(|v| v.length() > 1e-5),
            "the plate is sagging"
        );
        let rest = xr.solver().mesh().rest_positions.clone();
        let pins = pinned_nodes(xr.solver());
        assert!(!pins.is_empty());
        assert!(
            before
                .iter()
                .zip(&rest)
                .any(|(a, b)| (*a - *b).length() > 1e-7)
        );
        xr.set_substeps(min).unwrap();
        let s = xr.solver();
        assert_eq!(s.params().substeps, min);
        assert_eq!(s.positions(), &before[..]);
        let changed = s
            .velocities()
            .iter()
            .zip(&moving)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            changed, 0,
            "the motion goes on: {changed} velocities changed"
        );
        assert_eq!(pinned_nodes(s), pins, "pins kept");
        assert_eq!(released_tets(s), cut, "the cut kept");
        let motion = s.tool().expect("the scalpel stays attached");
        assert_eq!(motion.to, pose);
        xr.step().unwrap();
        // Reset: rest positions, nominal substeps, the scalpel waiting until tracked.
        xr.reset().unwrap();
        assert_eq!(xr.solver().positions(), &rest[..]);
        assert_eq!(xr.solver().params().substeps, nominal);
        assert!(!xr.tool().1);
        assert!(released_tets(xr.solver()).is_empty(), "reset heals the cut");
    }

    /// The tets `s` has released.
    fn released_tets(s: &Solver) -> Vec<usize> {
        (0..s.mesh().tet_count())
            .filter(|&i| !s.cut().is_live(i))
            .collect()
    }
}
