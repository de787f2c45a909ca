//! The right controller as the scalpel: the tool frame held at a fixed offset from the
//! grip pose, carried from stage space into the simulation's world through the tray.

use glam::{Mat3, Quat, Vec3};
use incise_sim::contact::ToolPose;

use super::pose::XrPose;
use super::tray::Tray;

/// Where the scalpel's frame sits in the controller's grip frame (OpenXR grip space: −z
/// along the closed hand's axis, +y up out of the back of the hand).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeOffset {
    /// Position of the blade tip (the tool frame's origin) in the grip frame, m.
    pub tip: Vec3,
    /// Orientation of the tool frame in the grip frame.
    pub rotation: Quat,
}

impl Default for BladeOffset {
    /// The scalpel held like a pen along the controller: the blade tip 12 cm ahead of and
    /// 2 cm below the grip; the tool's +x (handle → tip) along grip −z, its +z (the
    /// blade's back, away from the edge) along grip +y, so the edge faces down.
    fn default() -> Self {
        BladeOffset {
            tip: Vec3::new(0.0, -0.02, -0.12),
            rotation: Quat::from_mat3(&Mat3::from_cols(-Vec3::Z, -Vec3::X, Vec3::Y)),
        }
    }
}

/// The scalpel's pose in the simulation world for the right grip `grip` (stage space):
/// `sim_from_stage · grip · offset`. The tool keeps its own size: a scaled tray scales
/// the positions it reaches, not the blade.
pub fn scalpel_pose(grip: XrPose, offset: BladeOffset, tray: &Tray) -> ToolPose {
    let tip_stage = grip.position + grip.orientation * offset.tip;
    let rot_stage = grip.orientation * offset.rotation;
    ToolPose {
        position: tray.sim_from_stage().transform_point3(tip_stage),
        rotation: (tray.stage_from_sim_rotation().inverse() * rot_stage).normalize(),
    }
}

/// The right grip pose that puts the scalpel at `tool` (sim world): the inverse of
/// [`scalpel_pose`], for scripted controllers.
pub fn grip_for_scalpel(tool: ToolPose, offset: BladeOffset, tray: &Tray) -> XrPose {
    let tip_stage = tray.stage_from_sim().transform_point3(tool.position);
    let rot_stage = tray.stage_from_sim_rotation() * tool.rotation;
    let orientation = (rot_stage * offset.rotation.inverse()).normalize();
    XrPose {
        position: tip_stage - orientation * offset.tip,
        orientation,
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::FRAC_PI_2;

    use super::*;

    #[test]
    fn the_default_offset_is_a_rotation_pointing_the_tip_forward_and_the_edge_down() {
        let o = BladeOffset::default();
        assert!((o.rotation.length() - 1.0).abs() < 1e-6);
        assert!((o.rotation * Vec3::X - -Vec3::Z).length() < 1e-6);
        assert!((o.rotation * Vec3::Z - Vec3::Y).length() < 1e-6);
        assert!((o.rotation * Vec3::Y - -Vec3::X).length() < 1e-6);
    }

    #[test]
    fn controller_to_scalpel_by_hand() {
        // Tray at its default place for a 10 cm cube: anchor (0.05, 0.05, 0) on (0, 0.9, −0.45).
        let tray = Tray::for_bounds(Vec3::ZERO, Vec3::splat(0.1));
        // Grip level, facing −z, 30 cm above the tray centre.
        let grip = XrPose::new(Vec3::new(0.0, 1.2, -0.45), Quat::IDENTITY);
        let pose = scalpel_pose(grip, BladeOffset::default(), &tray);
        // Tip in stage: (0, 1.18, −0.57) → relative to the tray centre (0, 0.28, −0.12):
        // sim z = 0.28, sim y = +0.12 (stage −z), so (0.05, 0.17, 0.28).
        assert!(
            (pose.position - Vec3::new(0.05, 0.17, 0.28)).length() < 1e-5,
            "{}",
            pose.position
        );
        // Tool +x (tip direction) = stage −z = sim +y; tool +z = stage +y = sim +z.
        assert!((pose.rotation * Vec3::X - Vec3::Y).length() < 1e-5);
        assert!((pose.rotation * Vec3::Z - Vec3::Z).length() < 1e-5);

        // Turn the hand 90° to the left (about +y): the tip points along stage −x = sim −x.
        let turned = XrPose::new(grip.position, Quat::from_rotation_y(FRAC_PI_2));
        let pose = scalpel_pose(turned, BladeOffset::default(), &tray);
        assert!((pose.rotation * Vec3::X - -Vec3::X).length() < 1e-5);
        // The tip is 12 cm along −x and 2 cm below the grip: stage (−0.12, 1.18, −0.45).
        assert!(
            (pose.position - Vec3::new(-0.07, 0.05, 0.28)).length() < 1e-5,
            "{}",
            pose.position
        );

        // A doubled tray halves the distances in sim units.
        let big = Tray { scale: 2.0, ..tray };
        let pose = scalpel_pose(grip, BladeOffset::default(), &big);
        assert!(
            (pose.position - Vec3::new(0.05, 0.11, 0.14)).length() < 1e-5,
            "{}",
            pose.position
        );
    }

    #[test]
    fn the_inverse_gives_back_the_grip() {
        let tray = Tray {
            yaw: 0.7,
            scale: 1.5,
            ..Tray::for_bounds(Vec3::ZERO, Vec3::splat(0.1))
        };
        let grip = XrPose::new(
            Vec3::new(0.1, 1.1, -0.3),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.5, 0.2),
        );
        let tool = scalpel_pose(grip, BladeOffset::default(), &tray);
        let back = grip_for_scalpel(tool, BladeOffset::default(), &tray);
        assert!((back.position - grip.position).length() < 1e-5, "{back:?}");
        assert!(back.orientation.dot(grip.orientation).abs() > 1.0 - 1e-6);
    }
}
