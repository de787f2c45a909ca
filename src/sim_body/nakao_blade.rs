//! The Nakao cutter's blade (PHYSICS.md §2.3): a straight cutting edge from heel to tip,
//! moved by the scene's `model.stroke` (at constant speed from its start time) or by a
//! hand's tool pose (the tip at the tool's origin, the edge hanging below it, turned with
//! the tool).

use glam::{DQuat, DVec3, Quat};
use incise_scalpel::Stroke;
use incise_sim::contact::ToolPose;
use incise_sim::mass_spring::MassSpringModel;
use incise_sim::nakao_cut::BladePose;

use super::interface::ToolInput;
use crate::scene::StrokeSpec;

/// The edge of a hand-held blade when the scene gives none: 8 mm, heel below tip.
const DEFAULT_EDGE: DVec3 = DVec3::new(0.0, 0.0, 0.008);

/// A scene's blade: its scripted stroke, if any, and its edge (heel to tip).
#[derive(Debug, Clone)]
pub struct Blade {
    stroke: Option<StrokeSpec>,
    edge: DVec3,
}

impl Blade {
    /// The blade of a scene with `stroke` (its edge: the stroke's heel to tip).
    pub fn of_stroke(stroke: Option<StrokeSpec>) -> Blade {
        let edge = stroke
            .as_ref()
            .map_or(DEFAULT_EDGE, |s| (s.tip - s.heel).as_dvec3());
        Blade { stroke, edge }
    }

    /// The edge from heel to tip when the tool is unturned, m.
    pub fn edge(&self) -> DVec3 {
        self.edge
    }

    /// The scalpel that shows blade `pose` as `tool` put it there: a hand's pose as the
    /// hand holds it; the script's blade at its tip, turned about the vertical so that
    /// the tool frame's +x points along the stroke's travel, as the preview's mouse turns
    /// the blade toward its motion (`ScalpelInput::advance`).
    pub fn drawn(&self, tool: &ToolInput, pose: BladePose) -> ToolPose {
        if let ToolInput::Hand { pose, .. } = tool {
            return *pose;
        }
        let travel = self.stroke.as_ref().map_or(glam::Vec3::ZERO, |s| s.travel);
        let yaw = match travel.truncate() {
            t if t.length() > 0.0 => t.y.atan2(t.x),
            _ => 0.0,
        };
        ToolPose {
            position: pose.tip.as_vec3(),
            rotation: Quat::from_rotation_z(yaw),
        }
    }

    /// Where `tool` puts the blade at simulated time `t`, whether it cuts, and where a cut
    /// that starts now begins (`previous`: the blade's last pose); `None`: no blade.
    pub fn at(
        &self,
        tool: &ToolInput,
        t: f64,
        previous: Option<BladePose>,
    ) -> Option<(BladePose, bool, BladePose)> {
        match tool {
            ToolInput::Script => {
                let s = self.stroke.as_ref()?;
                let (pose, progress) = blade_at(s, t);
                let begin = blade_at(s, s.start as f64).0;
                Some((pose, progress > 0.0 && progress < 1.0, begin))
            }
            ToolInput::Hand { pose, engaged } => {
                let tip = pose.position.as_dvec3();
                let turn = DQuat::from_array(pose.rotation.to_array().map(f64::from));
                let blade = BladePose {
                    heel: tip - turn * self.edge,
                    tip,
                };
                Some((blade, *engaged, previous.unwrap_or(blade)))
            }
        }
    }
}

/// The blade's tool point, where the haptic coupling and the localisation act: the middle
/// of its cutting edge.
pub fn tool_point(pose: BladePose) -> DVec3 {
    (pose.heel + pose.tip) * 0.5
}

/// What a stroke file does to the blade at simulated time `t`, as a hand would: the tool
/// at the stroke's pose, cutting from the stroke's first key to its last except where
/// the recorded hand held it lifted (trigger or button up).
pub fn stroke_hand(stroke: &Stroke, t: f64) -> ToolInput {
    ToolInput::Hand {
        pose: stroke.pose_at(t),
        engaged: stroke.engaged_at(t),
    }
}

/// Whether blade `pose` touches `model`'s tissue: a point of its edge (heel, tip and
/// three between) within `reach` of a node.
pub fn touches(model: &MassSpringModel, pose: BladePose, reach: f64) -> bool {
    (0..=4).any(|k| {
        let p = pose.heel.lerp(pose.tip, k as f64 / 4.0);
        model
            .nearest_node(p)
            .is_some_and(|i| (model.positions()[i as usize] - p).length() <= reach)
    })
}

/// The tool pose that shows blade `pose`: at its tip, unturned (`None`: no blade yet).
pub fn tool_pose(pose: Option<BladePose>) -> Option<ToolPose> {
    pose.map(|p| ToolPose {
        position: p.tip.as_vec3(),
        rotation: Quat::IDENTITY,
    })
}

/// The blade pose at time `t` along stroke `s` and the stroke's progress (0 before it
/// starts, 1 at its end).
pub fn blade_at(s: &StrokeSpec, t: f64) -> (BladePose, f64) {
    let length = s.travel.length() as f64;
    let progress = if length > 0.0 {
        ((t - s.start as f64) * s.speed as f64 / length).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let d: DVec3 = s.travel.as_dvec3() * progress;
    (
        BladePose {
            heel: s.heel.as_dvec3() + d,
            tip: s.tip.as_dvec3() + d,
        },
        progress,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn stroke() -> StrokeSpec {
        StrokeSpec {
            heel: Vec3::new(0.0, 0.0, -0.002),
            tip: Vec3::new(0.0, 0.0, 0.006),
            travel: Vec3::new(0.1, 0.0, 0.0),
            speed: 0.2,
            start: 0.2,
        }
    }

    #[test]
    fn the_script_cuts_between_the_strokes_start_and_end() {
        let b = Blade::of_stroke(Some(stroke()));
        let (_, before, _) = b.at(&ToolInput::Script, 0.1, None).unwrap();
        let (pose, during, begin) = b.at(&ToolInput::Script, 0.45, None).unwrap();
        let (_, after, _) = b.at(&ToolInput::Script, 0.8, None).unwrap();
        assert!(!before && during && !after);
        assert!((pose.heel.x - 0.05).abs() < 1e-9 && begin.heel.x == 0.0);
    }

    #[test]
    fn a_hand_turns_the_edge_with_the_tool() {
        let b = Blade::of_stroke(Some(stroke()));
        let pose = ToolPose {
            position: Vec3::new(0.01, 0.0, 0.0),
            rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        };
        let hand = ToolInput::Hand {
            pose,
            engaged: true,
        };
        let (blade, engaged, begin) = b.at(&hand, 0.0, None).unwrap();
        assert!(engaged && begin == blade);
        // +z turned a quarter about y is +x: the 8 mm edge now lies along x, its tip at
        // the tool's origin.
        assert!((blade.tip - blade.heel - DVec3::new(0.008, 0.0, 0.0)).length() < 1e-6);
        assert!((blade.tip - DVec3::new(0.01, 0.0, 0.0)).length() < 1e-6);
    }
}
