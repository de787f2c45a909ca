//! How a configuration file describes a stroke: a stroke file, or a straight incision
//! generated for the tool that cuts it (scenes and the simulated headset's script).

use glam::{Quat, Vec3};
use serde::Deserialize;

use crate::error::FieldError;
use crate::incision::Incision;
use crate::stroke::Stroke;
use crate::tool::Tool;

/// How the tool moves.
#[derive(Debug, Clone, Deserialize)]
pub enum ToolStroke {
    /// A stroke file (timed poses, RON), relative to the file that names it.
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

impl IncisionSpec {
    /// The stroke of this incision with `tool`: the blade stands vertical in the plane of
    /// the line, handle towards `end` and raised by `angle_deg`; the tip rides high
    /// enough that the edge's lowest point reaches `depth`.
    pub fn stroke(&self, tool: &Tool) -> Result<Stroke, FieldError> {
        let dir = (self.end - self.start) * Vec3::new(1.0, 1.0, 0.0);
        if dir.length() < 1e-6 {
            return Err(FieldError::new(
                "end",
                "start and end must differ horizontally",
            ));
        }
        if !(self.angle_deg.is_finite() && (0.0..90.0).contains(&self.angle_deg)) {
            return Err(FieldError::new(
                "angle_deg",
                format!("must be in [0, 90) degrees, got {}", self.angle_deg),
            ));
        }
        // Pitch about the blade normal so that +x (towards the handle) rises, then yaw.
        let pitch = Quat::from_rotation_y(-self.angle_deg.to_radians());
        let rotation = Quat::from_rotation_arc(Vec3::X, dir.normalize()) * pitch;
        let drop = -tool
            .edge()
            .iter()
            .map(|p| (rotation * Vec3::new(p.x, 0.0, p.y)).z)
            .fold(0.0, f32::min);
        let lift = Vec3::Z * drop;
        Incision {
            start: self.start + lift,
            end: self.end + lift,
            depth: self.depth,
            rotation,
            approach: self.approach,
            speed: self.speed,
            dt_key: 0.05,
            up: Vec3::Z,
        }
        .stroke()
    }
}
