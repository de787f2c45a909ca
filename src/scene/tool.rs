//! The scene's scalpel: which tool file and which stroke drives it (issue 5).

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::{Quat, Vec3};
use incise_scalpel::{Incision, Stroke, Tool, load_stroke, load_tool};
use serde::Deserialize;

/// The scalpel of a scene: a tool file, relative to the scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolSpec {
    /// Tool file (RON, e.g. `tools/scalpel_10.ron`), relative to the scene file.
    pub file: String,
    /// A dull blade: the edge spheres push but never cut.
    #[serde(default)]
    pub dull: bool,
}

/// How the tool moves.
#[derive(Debug, Clone, Deserialize)]
pub enum ToolStroke {
    /// A stroke file (timed poses, RON), relative to the scene file.
    File(String),
    /// A straight incision on the tissue surface, blade vertical, drawn belly first
    /// (handle leading) from `start` to `end`.
    Incision(IncisionSpec),
}

/// A scripted straight incision (the stroke is generated at load time).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IncisionSpec {
    /// Start of the incision line on the tissue surface, m.
    pub start: Vec3,
    /// End of the line, m.
    pub end: Vec3,
    /// Depth of the cutting edge's lowest point below the line, m.
    pub depth: f32,
    /// Blade speed, m/s.
    #[serde(default = "default_speed")]
    pub speed: f32,
    /// Height above the surface where the blade starts and finishes, m.
    #[serde(default = "default_approach")]
    pub approach: f32,
    /// Elevation of the handle above the surface, degrees (the blade tilts in its own
    /// plane; a No. 10 is drawn at about 30–45°).
    #[serde(default = "default_angle")]
    pub angle_deg: f32,
}

fn default_angle() -> f32 {
    40.0
}

fn default_speed() -> f32 {
    0.02
}

fn default_approach() -> f32 {
    0.01
}

/// Load the tool and build the stroke of a scene.
pub fn load(tool: &ToolSpec, stroke: &ToolStroke, scene_path: &Path) -> Result<(Tool, Stroke)> {
    let dir = scene_path.parent().unwrap_or(Path::new("."));
    let t = load_tool(&dir.join(&tool.file))
        .with_context(|| format!("{}: tool", scene_path.display()))?;
    let s = match stroke {
        ToolStroke::File(f) => load_stroke(&dir.join(f))
            .with_context(|| format!("{}: stroke", scene_path.display()))?,
        ToolStroke::Incision(i) => {
            incision(&t, i).with_context(|| format!("{}: stroke.Incision", scene_path.display()))?
        }
    };
    Ok((t, s))
}

/// The stroke of a straight incision with this tool: the blade stands vertical in the
/// plane of the line, handle towards `end` and raised by `angle_deg`; the tip rides high
/// enough that the edge's lowest point reaches `depth`.
pub fn incision(tool: &Tool, spec: &IncisionSpec) -> Result<Stroke> {
    let dir = (spec.end - spec.start) * Vec3::new(1.0, 1.0, 0.0);
    if dir.length() < 1e-6 {
        bail!("start and end must differ horizontally");
    }
    if !(spec.angle_deg.is_finite() && (0.0..90.0).contains(&spec.angle_deg)) {
        bail!(
            "angle_deg must be in [0, 90) degrees, got {}",
            spec.angle_deg
        );
    }
    // Pitch about the blade normal so that +x (towards the handle) rises, then yaw.
    let pitch = Quat::from_rotation_y(-spec.angle_deg.to_radians());
    let rotation = Quat::from_rotation_arc(Vec3::X, dir.normalize()) * pitch;
    let drop = -tool
        .edge()
        .iter()
        .map(|p| (rotation * Vec3::new(p.x, 0.0, p.y)).z)
        .fold(0.0, f32::min);
    let lift = Vec3::Z * drop;
    let i = Incision {
        start: spec.start + lift,
        end: spec.end + lift,
        depth: spec.depth,
        rotation,
        approach: spec.approach,
        speed: spec.speed,
        dt_key: 0.05,
        up: Vec3::Z,
    };
    Ok(i.stroke()?)
}
