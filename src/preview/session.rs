//! The simulation behind the preview: the chosen scene, its body on the chosen device,
//! stepping, reset, and material/solver settings changed while it runs (the body is
//! rebuilt around the current positions, cut and grab progress).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use incise_sim::contact::CutZone;
use incise_sim::grab::Grab;
use incise_sim::skin::Skin;
use incise_sim::xpbd::FrameStats;
use incise_sim::{Material, Solver};
use incise_xr::RenderDevice;

use super::hand_tool::HandTool;
use crate::pictures::screenshots::{default_camera, place_on};
use crate::scene::hand_tool::edge_zone;
use crate::scene::{Scene, ToolDriver, build_scene_driven, load_scene};
use crate::sim_body::{Body, DeviceChoice};

/// Settings the panel changes while the scene runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveParams {
    /// Young's modulus, Pa.
    pub youngs_modulus: f32,
    /// Poisson ratio.
    pub poisson_ratio: f32,
    /// Velocity damping, 1/s.
    pub damping: f32,
    /// von Mises cut threshold, Pa (`None`: no cutting).
    pub cut_threshold: Option<f32>,
    /// Where the cut criterion may release tets (the scene's own unless the panel's
    /// switch changed it).
    pub cut_zone: CutZone,
    /// The zone the panel's "only along the blade's edge" switch gives (the scene's own
    /// `NearEdge`, else [`edge_zone`] for this mesh; not editable).
    pub edge_zone: CutZone,
    /// Substeps per frame.
    pub substeps: u32,
    /// The Poisson ratios the scene's constraint pair can represent (not editable).
    pub poisson_range: (f32, f32),
}

/// A scene running in the preview.
pub struct Session {
    /// The scene file.
    pub path: PathBuf,
    scene: Scene,
    /// The body.
    pub body: Body,
    /// The skin embedded in the body's mesh.
    pub skin: Skin,
    /// The device the body runs on (cpu or gpu).
    pub device: DeviceChoice,
    /// Settings in force.
    pub params: LiveParams,
    /// Pinned nodes.
    pub pinned: Vec<u32>,
    /// Density of the material, kg/m³ (not editable).
    density: f32,
    /// The last solver failure, shown in the panel.
    pub error: Option<String>,
    /// The scalpel (the scene's, else the built-in No. 10), driven by the mouse or the
    /// scene's stroke.
    pub hand: HandTool,
}

/// `.ron` files in `dir` that are not presets files (scenes, or exercises in theirs),
/// sorted.
pub fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron") && !is_presets(p))
        .collect();
    v.sort();
    v
}

/// Whether the RON file `path` is a presets file (`materials.ron`, rheology presets): a
/// map of named entries, where a scene or an exercise is a struct `( .. )`.
fn is_presets(path: &Path) -> bool {
    std::fs::read_to_string(path).is_ok_and(|text| {
        ron::from_str::<std::collections::BTreeMap<String, ron::Value>>(&text).is_ok()
    })
}

impl Session {
    /// Load `path` and put its body on `device` (the GPU one on `dev`).
    pub fn load(path: &Path, device: DeviceChoice, dev: &RenderDevice) -> Result<Session> {
        let scene = load_scene(path)?;
        let mut built = build_scene_driven(&scene, path, None, ToolDriver::Hand)?;
        let yaw = default_camera(built.solver.mesh()).yaw;
        let hand = HandTool::for_scene(&mut built, yaw)
            .with_context(|| format!("{}: tool", path.display()))?;
        let p = built.solver.params().clone();
        let params = LiveParams {
            youngs_modulus: built.material.youngs_modulus,
            poisson_ratio: built.material.poisson_ratio,
            damping: p.damping,
            cut_threshold: p.release_threshold,
            cut_zone: p.cut_zone,
            edge_zone: match p.cut_zone {
                CutZone::Anywhere => edge_zone(built.solver.mesh().mean_edge_length()),
                own => own,
            },
            substeps: p.substeps,
            poisson_range: p.poisson_range(),
        };
        let pinned = incise_xr::frame::pinned_nodes(&built.solver);
        Ok(Session {
            path: path.to_path_buf(),
            density: built.material.density,
            body: place_on(built.solver, device, dev)?,
            skin: built.skin,
            scene,
            device,
            params,
            pinned,
            error: None,
            hand,
        })
    }

    /// Start recording a stroke: the scene is loaded again as its file says (frame 0,
    /// its own settings, so `incise run SCENE --stroke FILE` replays the same physics) and
    /// the blade keeps its place and mouse state.
    pub fn start_recording(&mut self, dev: &RenderDevice) -> Result<()> {
        self.reload(dev)?;
        self.hand.start_recording(&mut self.body)
    }

    /// Load the scene again as its file says (frame 0, its own settings); the blade keeps
    /// its place and mouse state.
    pub fn reload(&mut self, dev: &RenderDevice) -> Result<()> {
        let mut fresh = Session::load(&self.path, self.device, dev)?;
        fresh.hand.input = self.hand.input.clone();
        fresh.hand.play_stroke = self.hand.play_stroke && fresh.hand.has_stroke();
        *self = fresh;
        Ok(())
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.scene.name
    }

    /// Step one frame; a solver failure is kept in [`Session::error`] and returned.
    pub fn step(&mut self) -> Result<(FrameStats, f64), String> {
        let t0 = Instant::now();
        if let Err(e) = self.hand.before_step(&mut self.body) {
            let msg = format!("{e:#}");
            self.error = Some(msg.clone());
            return Err(msg);
        }
        match self.body.step_frame() {
            Ok(s) => {
                self.hand.after_step(&s);
                Ok((s, t0.elapsed().as_secs_f64() * 1e3))
            }
            Err(e) => {
                let msg = e.to_string();
                self.error = Some(msg.clone());
                Err(msg)
            }
        }
    }

    /// Start over from rest with the current settings.
    pub fn reset(&mut self, dev: &RenderDevice) -> Result<()> {
        let solver = self.rest_solver()?;
        self.body = place_on(solver, self.device, dev)?;
        self.error = None;
        Ok(())
    }

    /// Apply `params` (and `device`) to the running body: a new solver with the new
    /// material and settings continues from the current positions, cut and grab
    /// progress. Refused settings (unstable, out of range) leave the body as it was.
    pub fn apply(
        &mut self,
        params: LiveParams,
        device: DeviceChoice,
        dev: &RenderDevice,
    ) -> Result<()> {
        let old = self.params;
        self.params = params;
        // The new solver counts frames from 0: the scene's stroke would restart, so the
        // mouse takes the blade where the stroke has it now.
        let cur = self.body.solver();
        self.hand
            .take_mouse(cur.frame(), cur.params().frame_dt as f64);
        let solver = match self.continued_solver() {
            Ok(s) => s,
            Err(e) => {
                self.params = old;
                return Err(e);
            }
        };
        self.body = place_on(solver, device, dev)?;
        self.device = device;
        Ok(())
    }

    /// The material and solver settings the panel has in force.
    fn settings(&self) -> (Material, incise_sim::SolverParams) {
        let material = Material {
            youngs_modulus: self.params.youngs_modulus,
            poisson_ratio: self.params.poisson_ratio,
            density: self.density,
        };
        let mut sp = self.body.solver().params().clone();
        sp.damping = self.params.damping;
        sp.release_threshold = self.params.cut_threshold;
        sp.cut_zone = self.params.cut_zone;
        sp.substeps = self.params.substeps;
        (material, sp)
    }

    /// The running body with the current settings, continuing its motion, cut and grabs
    /// ([`Solver::retuned`]), the blade where the hand has it.
    fn continued_solver(&self) -> Result<Solver> {
        let (material, sp) = self.settings();
        let cur = self.body.solver();
        let mut s = cur
            .retuned(material, sp)
            .with_context(|| self.path.display().to_string())?;
        let (contact, pose) = (self.hand).attachment(cur.frame(), cur.params().frame_dt as f64);
        s.set_tool(contact, pose)
            .with_context(|| format!("{}: tool", self.path.display()))?;
        Ok(s)
    }

    /// A solver for this scene at rest with the current settings.
    fn rest_solver(&self) -> Result<Solver> {
        let (material, sp) = self.settings();
        let cur = self.body.solver();
        let mesh = cur.mesh().clone();
        let rest = mesh.rest_positions.clone();
        let mut s =
            Solver::new(mesh, material, sp).with_context(|| self.path.display().to_string())?;
        s.pin(&self.pinned);
        let (contact, pose) = self.hand.attachment(0, cur.params().frame_dt as f64);
        s.set_tool(contact, pose)
            .with_context(|| format!("{}: tool", self.path.display()))?;
        for (i, g) in self.scene.grabs.iter().enumerate() {
            let nodes = g
                .nodes
                .select(&rest)
                .with_context(|| format!("{}: grabs[{i}].nodes", self.path.display()))?;
            s.add_grab(Grab {
                nodes,
                waypoints: g.path.clone(),
                speed: g.speed,
                start_time: g.start,
            });
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// config/ offers its scenes but not its two presets files (materials, rheology), and
    /// a copy of a presets file under another name is known by its content.
    #[test]
    fn the_scene_list_leaves_out_presets_files() {
        let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
        let names = |dir: &Path| -> Vec<String> {
            scene_files(dir)
                .iter()
                .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                .collect()
        };
        let listed = names(&config);
        for scene in ["plate_cut.ron", "plate_cut_nakao.ron", "organ_layers.ron"] {
            assert!(listed.contains(&scene.to_string()), "{scene}: {listed:?}");
        }
        for presets in ["materials.ron", "rheology.ron"] {
            assert!(
                !listed.contains(&presets.to_string()),
                "{presets}: {listed:?}"
            );
        }
        let dir = std::env::temp_dir().join(format!("incise-scene-list-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(config.join("rheology.ron"), dir.join("soft.ron")).unwrap();
        std::fs::copy(config.join("plate_cut.ron"), dir.join("cut.ron")).unwrap();
        assert_eq!(names(&dir), ["cut.ron"]);
        assert_eq!(names(&config.join("exercises")).len(), 4);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A slider moved during a pull: the new body goes on from where the grab had taken
    /// the tissue (as the same frames would without the change), neither restarting the
    /// grab's path nor dropping it.
    #[test]
    fn a_setting_changed_mid_pull_keeps_the_grab_going() {
        let gate = incise_test_gate::Need::Gpu;
        let Some(dev) = incise_test_gate::or_skip(gate, RenderDevice::headless()) else {
            return;
        };
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/plate_stretch.ron");
        let open = || Session::load(&path, DeviceChoice::Cpu, &dev).unwrap();
        let (mut same, mut tuned) = (open(), open());
        for s in [&mut same, &mut tuned] {
            for _ in 0..20 {
                s.step().unwrap();
            }
        }
        let params = LiveParams {
            damping: tuned.params.damping * 1.001,
            ..tuned.params
        };
        tuned.apply(params, DeviceChoice::Cpu, &dev).unwrap();
        assert_eq!(tuned.body.solver().frame(), 20, "the frame count goes on");
        for s in [&mut same, &mut tuned] {
            for _ in 0..20 {
                s.step().unwrap();
            }
        }
        let (a, b) = (
            same.body.solver().positions(),
            tuned.body.solver().positions(),
        );
        let moved = a
            .iter()
            .zip(&same.body.solver().mesh().rest_positions)
            .map(|(p, r)| (*p - *r).length())
            .fold(0.0f32, f32::max);
        let apart = a
            .iter()
            .zip(b)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0f32, f32::max);
        assert!(moved > 1e-3, "the grab pulls the plate: {moved} m");
        assert!(
            apart < 0.01 * moved,
            "a 0.1 % damping change moved the body {apart} m of {moved}"
        );
    }

    /// The panel's "only along the blade's edge" switch on a tearing scene: on (the edge
    /// zone applied to the running body) the grab stretches the plate without releasing a
    /// tet, the blade being parked away from it; off again, the same body tears where the
    /// stress passes the threshold, as `incise run` does.
    #[test]
    fn the_edge_zone_switch_stops_and_restores_tearing() {
        let gate = incise_test_gate::Need::Gpu;
        let Some(dev) = incise_test_gate::or_skip(gate, RenderDevice::headless()) else {
            return;
        };
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/plate_stretch.ron");
        let mut s = Session::load(&path, DeviceChoice::Cpu, &dev).unwrap();
        assert_eq!(s.params.cut_zone, CutZone::Anywhere, "the scene's own zone");
        let released = |s: &Session| s.body.solver().cut().released_count();
        let edge = LiveParams {
            cut_zone: s.params.edge_zone,
            ..s.params
        };
        s.apply(edge, DeviceChoice::Cpu, &dev).unwrap();
        assert_eq!(s.body.solver().params().cut_zone, s.params.edge_zone);
        for _ in 0..150 {
            s.step().unwrap();
        }
        assert_eq!(released(&s), 0, "the edge zone tore the plate");
        let anywhere = LiveParams {
            cut_zone: CutZone::Anywhere,
            ..s.params
        };
        s.apply(anywhere, DeviceChoice::Cpu, &dev).unwrap();
        for _ in 0..5 {
            s.step().unwrap();
        }
        assert!(released(&s) > 0, "switched off, the stretched plate tears");
    }
}
