//! report.json: what a run did, frame by frame, in a form scripts can compare.
//!
//! Each model reports the quantities it computes: the XPBD solver its stresses and
//! releases, the edge models (mass-spring, rheology) displacement, volume and energy. A
//! quantity a model does not compute is left out, never written as NaN or null.

pub mod localisation;
pub mod plot;

use std::path::Path;

use anyhow::{Context, Result};
use incise_sim::xpbd::FrameStats;
use serde::Serialize;

use crate::quantile::percentile;
use crate::scene::Method;
use crate::scene::Scene;

/// One frame's line in the report.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRecord {
    /// The model's statistics.
    #[serde(flatten)]
    pub stats: FrameData,
    /// Wall time of the frame (substeps + stress + release), ms.
    pub wall_ms: f64,
    /// GPU kernel time of the frame (timestamps), ms; absent on the CPU or without them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu_ms: Option<f64>,
    /// Controller vibration amplitude 0..1 for this frame's tool force (the scalpel's
    /// haptic curve); absent without a tool.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub haptic_amplitude: Option<f32>,
}

/// The scene's scalpel, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct ToolInfo {
    /// Tool name.
    pub name: String,
    /// Contact spheres.
    pub spheres: usize,
    /// Of which on the cutting edge.
    pub cutting_spheres: usize,
    /// Sphere radius, m.
    pub sphere_radius: f32,
    /// Body boxes.
    pub boxes: usize,
    /// Friction coefficient.
    pub friction: f32,
    /// Duration of the stroke, s.
    pub stroke_duration: f64,
}

/// A frame's statistics, by model (written flat into the frame's record).
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum FrameData {
    /// The XPBD Neo-Hookean solver: stresses, releases, contact.
    Xpbd(FrameStats),
    /// A model over tet edges (mass-spring or three-element rheology): no stress tensor.
    Edges(EdgeFrameStats),
}

/// What one frame of an edge model (mass-spring, rheology) did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct EdgeFrameStats {
    /// Frame index (0-based).
    pub frame: u64,
    /// Simulation time at the end of the frame, s.
    pub sim_time: f64,
    /// Integration steps taken in the frame (haptic-rate runs: haptic loops).
    pub substeps: u64,
    /// Current volume of the tets over their reference volume.
    pub volume_ratio: f64,
    /// Largest node displacement from the reference position, m.
    pub max_displacement: f64,
    /// Kinetic energy ½ Σ m v², J (haptic-rate runs: at the thread's last snapshot).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kinetic_energy: Option<f64>,
    /// Wall time of the integration, ms (absent in a haptic-rate run, whose integration
    /// runs on the haptic thread).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solve_ms: Option<f64>,
    /// Latest force of the tissue on the tool (x, y, z), N: a haptic-rate run's haptic
    /// tool, or a Nakao blade held by a hand (or a stroke file).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool_force: Option<[f64; 3]>,
    /// Whether the engaged blade touched the tissue (its edge within half a mean edge
    /// length of a node); frame-by-frame Nakao runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blade_contact: Option<bool>,
    /// Haptic loops run so far; haptic-rate runs only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub haptic_loops: Option<u64>,
    /// Localisation level the frame reached; localised mass-spring runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub level: Option<u32>,
    /// Nodes integrated in the frame; mass-spring runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub free_nodes: Option<usize>,
    /// The frame's localisation (nearest node, hierarchy), ms; mass-spring runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub localise_ms: Option<f64>,
    /// The frame's spring-force computation, ms; mass-spring runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_ms: Option<f64>,
    /// The frame's velocity and position updates, ms; mass-spring runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrate_ms: Option<f64>,
    /// The frame's blade advance (crossings, subdivision, remodelling), ms; mass-spring runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_ms: Option<f64>,
    /// Depth of the indenter face below the rest top, m; rheology scenes with an indenter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub indenter_depth: Option<f64>,
    /// Depth of the probe node (top node under the indenter's centre) below its rest
    /// height, m; rheology scenes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dent_depth: Option<f64>,
}

/// The whole run report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Scene name.
    pub scene: String,
    /// Scene file.
    pub scene_file: String,
    /// Simulation model: "xpbd", "mass-spring" or "rheology".
    pub model: String,
    /// Simulation method: "xpbd", "nakao" or "rheology" (every report has this schema).
    pub method: Method,
    /// "completed" or "failed".
    pub status: String,
    /// The error that stopped the run, if any.
    pub error: Option<String>,
    /// Mesh figures.
    pub mesh: MeshInfo,
    /// Material name and values (absent for rheology scenes: see `rheology`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialInfo>,
    /// Solver settings in use.
    pub solver: incise_sim::SolverParams,
    /// Worker threads used.
    pub threads: usize,
    /// Device the solver ran on: "cpu" or the GPU adapter's name, backend and type.
    pub device: String,
    /// With `--device auto`: which device it picked and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device_choice: Option<String>,
    /// The scalpel, when the scene has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool: Option<ToolInfo>,
    /// What went wrong but did not stop the run (e.g. a GPU lost and the CPU taking over).
    pub warnings: Vec<String>,
    /// Tets released by the end of the run (mesh indices, ascending).
    pub released_tets: Vec<u32>,
    /// Per-frame records.
    pub frames: Vec<FrameRecord>,
    /// Snapshot files written (relative to the report).
    pub snapshots: Vec<String>,
    /// Materials per region and dent figures of a rheology scene.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rheology: Option<RheologyInfo>,
    /// What the Nakao cutter did to the mesh: added nodes and tets, the wound's opening.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nakao: Option<NakaoInfo>,
    /// Loop rate and tool force of a haptic-rate run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub haptic: Option<HapticInfo>,
    /// Levels, free nodes and loop-time split over the frames of a mass-spring run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub localisation: Option<localisation::LocalisationInfo>,
}

/// Mesh figures for the report.
#[derive(Debug, Clone, Serialize)]
pub struct MeshInfo {
    /// Nodes.
    pub nodes: usize,
    /// Tets.
    pub tets: usize,
    /// Tets re-oriented on load.
    pub reoriented_tets: usize,
    /// Colours of the parallel projection.
    pub colors: usize,
    /// Skin vertices.
    pub skin_vertices: usize,
    /// Skin triangles.
    pub skin_triangles: usize,
    /// Pinned nodes.
    pub pinned_nodes: usize,
    /// Grabbed nodes.
    pub grabbed_nodes: usize,
    /// Reader warnings.
    pub warnings: Vec<String>,
}

/// Material for the report.
#[derive(Debug, Clone, Serialize)]
pub struct MaterialInfo {
    /// Preset name or "custom".
    pub name: String,
    /// E, ν, ρ.
    #[serde(flatten)]
    pub values: incise_sim::Material,
    /// Shear modulus μ, Pa.
    pub mu: f32,
    /// Lamé λ, Pa.
    pub lambda: f32,
}

/// One material of a rheology scene and how much of the mesh takes it.
#[derive(Debug, Clone, Serialize)]
pub struct RegionMaterialInfo {
    /// "default" or `regions[i]`.
    pub region: String,
    /// Preset name in the preset file.
    pub preset: String,
    /// Tets that take it (a later region wins over an earlier one).
    pub tets: usize,
    /// Edges that take it.
    pub edges: usize,
}

/// Rheology-specific figures (PHYSICS.md §3).
#[derive(Debug, Clone, Serialize)]
pub struct RheologyInfo {
    /// The preset file used.
    pub presets_file: String,
    /// Default material, then each region.
    pub materials: Vec<RegionMaterialInfo>,
    /// Explicit RK4 stability limit, s.
    pub stability_limit_s: f64,
    /// RK4 step used, s.
    pub step_s: f64,
    /// Largest probe depth over the run, m.
    pub max_dent_m: f64,
    /// Probe depth at the end of the run, m.
    pub residual_dent_m: f64,
}

/// The Nakao cutter's result (PHYSICS.md §2.3–2.4, §2.6): what cutting added to the
/// mesh and how far the wound opened under the tension.
#[derive(Debug, Clone, Serialize)]
pub struct NakaoInfo {
    /// Nodes the cut added (duplicated and subdivision nodes).
    pub nodes_added: usize,
    /// Tets the cut added (subdivision).
    pub tets_added: usize,
    /// Area of the cut surfaces at the end, m².
    pub cut_area_m2: f64,
    /// Mean distance between the two copies of every node the cut duplicated, m (absent
    /// when nothing was cut).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub opening_width_m: Option<f64>,
}

/// What the haptic-rate loop did (PHYSICS.md §2.6), all measured, none assumed.
#[derive(Debug, Clone, Serialize)]
pub struct HapticInfo {
    /// Loop rate asked for, Hz.
    pub requested_hz: f64,
    /// Loops counted by the haptic thread over `wall_s`.
    pub loops: u64,
    /// Wall time from starting the thread to the last reading of its loop count, s.
    pub wall_s: f64,
    /// `loops / wall_s`, Hz.
    pub achieved_hz: f64,
    /// Loops that overran their period.
    pub overruns: u64,
    /// Simulated time the haptic thread reached, s.
    pub sim_time: f64,
    /// Position snapshots it published for the report loop.
    pub snapshots: u64,
    /// Report-loop rate, Hz (1 / the scene's frame_dt).
    pub report_hz: f64,
    /// Blade advances the haptic thread cut.
    pub cut_advances: u64,
    /// Tool force at the last frame (x, y, z), N.
    pub last_tool_force: [f64; 3],
    /// Largest tool force magnitude seen by the report loop, N.
    pub max_tool_force: f64,
}

impl Report {
    /// A running report of `scene` (file `path`) for model name and method `model`, with
    /// its mesh figures and solver settings; the rest is filled by the body and the run.
    pub fn begin(
        scene: &Scene,
        path: &Path,
        model: (&str, Method),
        mesh: MeshInfo,
        solver: incise_sim::SolverParams,
    ) -> Report {
        Report {
            scene: scene.name.clone(),
            scene_file: path.display().to_string(),
            model: model.0.into(),
            method: model.1,
            status: "running".into(),
            error: None,
            mesh,
            material: None,
            solver,
            threads: 1,
            device: "cpu".into(),
            device_choice: None,
            tool: None,
            warnings: Vec::new(),
            released_tets: Vec::new(),
            frames: Vec::new(),
            snapshots: Vec::new(),
            rheology: None,
            nakao: None,
            haptic: None,
            localisation: None,
        }
    }

    /// Write as pretty JSON, atomically (temp file + rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        let json = serde_json::to_vec_pretty(self)?;
        incise_sim::io::write_atomic(path, &json)
            .with_context(|| format!("writing {}", path.display()))
    }

    /// One line saying what the run did, in the quantities its model has, and what its
    /// frames cost in wall time.
    pub fn summary(&self) -> String {
        let line = self.outcome();
        match self.timing() {
            Some(t) => format!("{line}; {t}"),
            None => line,
        }
    }

    /// The frames' wall time: the median and p95 frame and the frames a second the run
    /// sustained (its frames over their summed time); `None` without frames.
    fn timing(&self) -> Option<String> {
        let mut ms: Vec<f64> = self.frames.iter().map(|f| f.wall_ms).collect();
        if ms.is_empty() {
            return None;
        }
        let mean = ms.iter().sum::<f64>() / ms.len() as f64;
        ms.sort_by(f64::total_cmp);
        Some(format!(
            "{:.1} ms a frame at the median, {:.1} at p95, {:.1} frames a second sustained",
            percentile(&ms, 0.5),
            percentile(&ms, 0.95),
            1e3 / mean
        ))
    }

    /// What the run did, in the quantities its model has.
    fn outcome(&self) -> String {
        let n = self.frames.len();
        let head = format!("completed {n} frames of {}", self.scene);
        let last = self.frames.last().map(|f| &f.stats);
        match last {
            None => head,
            Some(FrameData::Xpbd(s)) => format!(
                "{head}: {} tets released, max von Mises {:.0} Pa",
                s.released_total, s.max_von_mises
            ),
            Some(FrameData::Edges(s)) => {
                let mut line = format!(
                    "{head} ({}): {} nodes, {} tets, max displacement {:.2} mm, volume ratio {:.4}",
                    self.model,
                    self.mesh.nodes,
                    self.mesh.tets,
                    s.max_displacement * 1e3,
                    s.volume_ratio
                );
                if let Some(r) = &self.rheology {
                    line += &format!(
                        ", dent max {:.2} mm, residual {:.2} mm",
                        r.max_dent_m * 1e3,
                        r.residual_dent_m * 1e3
                    );
                }
                if let Some(n) = &self.nakao {
                    line += &format!(
                        ", cut added {} nodes and {} tets",
                        n.nodes_added, n.tets_added
                    );
                    if let Some(w) = n.opening_width_m {
                        line += &format!(", wound open {:.2} mm", w * 1e3);
                    }
                }
                if let Some(l) = &self.localisation {
                    line += &format!(
                        ", localisation {}: {:.0}–{:.0} nodes, loop {:.2}–{:.2} ms",
                        l.mode, l.free_nodes.min, l.free_nodes.max, l.total_ms.min, l.total_ms.max
                    );
                    if let Some(level) = &l.level {
                        line += &format!(", level {:.0}–{:.0}", level.min, level.max);
                    }
                }
                if let Some(h) = &self.haptic {
                    line += &format!(
                        ", haptic loop {:.0} Hz measured ({} loops in {:.2} s, {:.0} Hz asked), \
                         max tool force {:.3} N",
                        h.achieved_hz, h.loops, h.wall_s, h.requested_hz, h.max_tool_force
                    );
                }
                line
            }
        }
    }
}
