//! Which simulation model a scene uses: the XPBD Neo-Hookean solver (default) or the
//! Nakao 2003 tension mass-spring cutter (PHYSICS.md §2).

use glam::Vec3;
use incise_sim::mass_spring::Tension;
use incise_sim::nakao_cut::CutParams;
use incise_sim::selection::NodeSelection;
use serde::Deserialize;

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
}

/// Settings of a mass-spring scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpringScene {
    /// Spring constant k of every edge, N/m.
    #[serde(default = "default_stiffness")]
    pub stiffness: f64,
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
    /// Cutter settings (`subdivision: Adaptive | NonAdaptive`, …).
    #[serde(default)]
    pub cut: CutParams,
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
