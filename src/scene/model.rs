//! Which simulation model a scene uses: the XPBD Neo-Hookean solver (default), the
//! Nakao 2003 tension mass-spring cutter (PHYSICS.md §2) or the three-element rheological
//! body with a material per region (PHYSICS.md §3).

use glam::{DVec2, Vec3};
use incise_sim::mass_spring::{HapticContact, StiffnessLaw, Tension};
use incise_sim::nakao_cut::CutParams;
use incise_sim::selection::NodeSelection;
use serde::Deserialize;

use super::Localisation;

/// The simulation model of a scene.
#[derive(Debug, Clone, Default, Deserialize)]
pub enum ModelChoice {
    /// XPBD with Neo-Hookean constraints and stress-based cutting (PHYSICS.md §1).
    #[default]
    Xpbd,
    /// The tension mass-spring model with blade cutting (PHYSICS.md §2). Node masses use
    /// the material's density; its Young's modulus and Poisson ratio are not used (the
    /// springs have their own constant).
    MassSpring(MassSpringScene),
    /// Three-element rheological elements on every tet edge, integrated with RK4
    /// (PHYSICS.md §3), each region of the mesh with its own preset.
    Rheology(RheologyScene),
}

impl ModelChoice {
    /// The simulation method the model runs.
    pub fn method(&self) -> super::Method {
        use super::Method;
        match self {
            ModelChoice::Xpbd => Method::Xpbd,
            ModelChoice::MassSpring(_) => Method::Nakao,
            ModelChoice::Rheology(_) => Method::Rheology,
        }
    }

    /// The model's name in a scene file when it is not XPBD (`MassSpring`, `Rheology`);
    /// `None` for XPBD.
    pub fn non_xpbd_name(&self) -> Option<&'static str> {
        match self {
            ModelChoice::Xpbd => None,
            ModelChoice::MassSpring(_) => Some("MassSpring"),
            ModelChoice::Rheology(_) => Some("Rheology"),
        }
    }
}

/// Settings of a rheology scene: the materials per region and an optional flat indenter.
///
/// Which tet and edge takes which material: every tet takes `material`, then each region
/// in order, a later region winning. A `Nodes` region covers the tets whose **four** nodes
/// it selects (a tet straddling its border stays outside), a `Tets` region the tets it
/// lists. An edge takes the material of the last-listed region among the tets that share
/// it, so the edges on an interface between two regions belong to the later one. Node
/// masses use each tet's own density.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RheologyScene {
    /// The preset file, relative to the scene file.
    #[serde(default = "default_presets")]
    pub presets: String,
    /// Preset name of every tet outside the regions.
    pub material: String,
    /// Regions with their own preset, in order (a later one wins where they overlap).
    #[serde(default)]
    pub regions: Vec<RegionSpec>,
    /// A rigid flat indenter pressing the body's top; absent: none (gravity or pins only).
    #[serde(default)]
    pub indenter: Option<IndenterSpec>,
}

fn default_presets() -> String {
    "rheology.ron".into()
}

/// A part of the mesh and the preset it takes.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    /// Which tets.
    pub tets: RegionSelect,
    /// Preset name in the scene's preset file.
    pub material: String,
}

/// How a region picks its tets.
#[derive(Debug, Clone, Deserialize)]
pub enum RegionSelect {
    /// The tets whose four nodes the selection picks (by rest position or index).
    Nodes(NodeSelection),
    /// Explicit 0-based tet indices.
    Tets(Vec<u32>),
}

/// A flat rectangular indenter over the mesh's top (highest rest z): pressed down to
/// `depth` in `press` s, held `hold` s, lifted in `lift` s (the seed's press-and-release).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IndenterSpec {
    /// Centre of the face in x, y, m.
    pub centre: DVec2,
    /// Half extents of the face in x, y, m.
    pub half_size: DVec2,
    /// Depth of the face below the rest top at full press, m.
    pub depth: f64,
    /// Press ramp, s.
    pub press: f64,
    /// Hold at full depth, s.
    #[serde(default)]
    pub hold: f64,
    /// Lift-off ramp, s.
    pub lift: f64,
}

impl RheologyScene {
    /// Ok, or the first bad field (dotted path) and why.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if self.material.trim().is_empty() {
            return Err(("model.material".into(), "must name a preset".into()));
        }
        for (i, r) in self.regions.iter().enumerate() {
            if r.material.trim().is_empty() {
                return Err((
                    format!("model.regions[{i}].material"),
                    "must name a preset".into(),
                ));
            }
            if let RegionSelect::Tets(list) = &r.tets {
                if list.is_empty() {
                    return Err((
                        format!("model.regions[{i}].tets"),
                        "lists no tet: a region must cover at least one".into(),
                    ));
                }
            }
        }
        if let Some(ind) = &self.indenter {
            let positive = |x: f64| x.is_finite() && x > 0.0;
            if !ind.centre.is_finite() {
                return Err(("model.indenter.centre".into(), "must be finite".into()));
            }
            if !(positive(ind.half_size.x) && positive(ind.half_size.y)) {
                return Err((
                    "model.indenter.half_size".into(),
                    format!("must be positive lengths in m, got {}", ind.half_size),
                ));
            }
            for (field, value) in [
                ("depth", ind.depth),
                ("press", ind.press),
                ("lift", ind.lift),
            ] {
                if !positive(value) {
                    return Err((
                        format!("model.indenter.{field}"),
                        format!("must be > 0, got {value}"),
                    ));
                }
            }
            if !(ind.hold.is_finite() && ind.hold >= 0.0) {
                return Err((
                    "model.indenter.hold".into(),
                    format!("must be >= 0 s, got {}", ind.hold),
                ));
            }
        }
        Ok(())
    }
}

/// Settings of a mass-spring scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpringScene {
    /// Spring constant k of every edge, N/m.
    #[serde(default = "default_stiffness")]
    pub stiffness: f64,
    /// How each edge's constant follows from `stiffness`: `TetVolume` (default: from the
    /// tets' volumes, so a cut region keeps its stiffness) or the paper's `Uniform`.
    #[serde(default)]
    pub stiffness_law: StiffnessLaw,
    /// Node damping b, N·s/m.
    #[serde(default = "default_damping")]
    pub damping: f64,
    /// Tension coefficient(s) of eq. 3: `Uniform(s)` or `PerAxis((sx, sy, sz))`.
    #[serde(default)]
    pub tension: Tension,
    /// Node sets held along some axes only (the scene's `pins` hold all three).
    #[serde(default)]
    pub hold: Vec<HoldSpec>,
    /// A scripted blade stroke; absent: no cutting.
    #[serde(default)]
    pub stroke: Option<StrokeSpec>,
    /// Cutter settings (`subdivision: Adaptive | NonAdaptive | Bielser`, …).
    #[serde(default)]
    pub cut: CutParams,
    /// Which nodes each frame integrates: `Whole` (default), `Level(d)` around the blade,
    /// or `Budget(ms)`, the refresh-rate manager (PHYSICS.md §2.5).
    #[serde(default)]
    pub localisation: Localisation,
    /// How a hand-held tool is coupled to the tissue: `NearestNode` (default: a spring to
    /// the node nearest the blade, which also holds the blade in the cut) or `GodObject`
    /// (a proxy riding the surface, Zilles & Salisbury 1995: pushes back, never pulls).
    #[serde(default)]
    pub haptic_contact: HapticContact,
}

fn default_stiffness() -> f64 {
    100.0
}

fn default_damping() -> f64 {
    0.05
}

/// Nodes held along the listed axes.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoldSpec {
    /// Which nodes.
    pub nodes: NodeSelection,
    /// Hold along x.
    #[serde(default)]
    pub x: bool,
    /// Hold along y.
    #[serde(default)]
    pub y: bool,
    /// Hold along z.
    #[serde(default)]
    pub z: bool,
}

/// A straight blade stroke: the cutting edge from `heel` to `tip` moves by `travel`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrokeSpec {
    /// Back end of the cutting edge at the start, m.
    pub heel: Vec3,
    /// Front end of the cutting edge at the start, m.
    pub tip: Vec3,
    /// Displacement of the blade over the stroke, m.
    pub travel: Vec3,
    /// Blade speed, m/s.
    pub speed: f32,
    /// Time the stroke starts, s.
    #[serde(default)]
    pub start: f32,
}

impl MassSpringScene {
    /// Ok, or the first bad field (dotted path) and why.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let params = incise_sim::mass_spring::MassSpringParams {
            stiffness: self.stiffness,
            stiffness_law: self.stiffness_law,
            damping: self.damping,
            tension: self.tension,
            ..Default::default()
        };
        if let Err(incise_sim::mass_spring::MassSpringError::BadParameter { field, msg }) =
            params.validate()
        {
            return Err((format!("model.{field}"), msg));
        }
        if let Err((field, msg)) = self.cut.validate() {
            return Err((format!("model.cut.{field}"), msg));
        }
        if let Err(msg) = self.localisation.validate() {
            return Err(("model.localisation".into(), msg));
        }
        if self.localisation != Localisation::Whole && self.stroke.is_none() {
            return Err((
                "model.localisation".into(),
                "localises around the blade, so the scene needs a model.stroke".into(),
            ));
        }
        if let Some(s) = &self.stroke {
            if !(s.heel.is_finite() && s.tip.is_finite() && s.travel.is_finite()) {
                return Err((
                    "model.stroke".into(),
                    "heel, tip and travel must be finite".into(),
                ));
            }
            if !(s.speed.is_finite() && s.speed > 0.0) {
                return Err((
                    "model.stroke.speed".into(),
                    format!("must be a positive speed in m/s, got {}", s.speed),
                ));
            }
            if !(s.start.is_finite() && s.start >= 0.0) {
                return Err((
                    "model.stroke.start".into(),
                    format!("must be >= 0 s, got {}", s.start),
                ));
            }
        }
        Ok(())
    }
}
