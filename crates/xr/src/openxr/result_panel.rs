//! Where the exercise's result card hangs in the room: upright above the far side of the
//! tray, turned to face the trainee's head, at a fixed physical size whatever the tray's
//! magnification. The renderer draws in simulation coordinates, so the placement is
//! returned there (see [`crate::RenderSettings::panel`]).

use glam::{Mat4, Quat, Vec3};

use super::tray::Tray;

/// Width of the card in the room, m (its height follows the image's aspect).
pub const PANEL_WIDTH: f32 = 0.40;
/// Height of the card's centre above the tray surface, m.
pub const PANEL_HEIGHT: f32 = 0.30;
/// How far beyond the tray centre (away from the trainee) the card hangs, m.
pub const PANEL_BEHIND: f32 = 0.15;

/// The card's placement (the unit square of its local xy plane → sim world) for an image
/// `aspect` = height / width, above `tray` and facing a head at `head` (stage space).
pub fn panel_transform(tray: &Tray, head: Vec3, aspect: f32) -> Mat4 {
    // Stage placement: behind the tray centre as seen from the head, at eye-friendly
    // height, facing the head horizontally (upright: image up is stage up).
    let mut away = tray.centre - head;
    away.y = 0.0;
    let away = away.try_normalize().unwrap_or(Vec3::NEG_Z);
    let centre = tray.centre + away * PANEL_BEHIND + Vec3::Y * PANEL_HEIGHT;
    // Local +z (the image's front) towards the head: yaw so that +z = −away.
    let yaw = (-away.x).atan2(-away.z);
    let stage_from_panel = Mat4::from_scale_rotation_translation(
        Vec3::new(PANEL_WIDTH, PANEL_WIDTH * aspect, 1.0),
        Quat::from_rotation_y(yaw),
        centre,
    );
    tray.sim_from_stage() * stage_from_panel
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tray() -> Tray {
        Tray::for_bounds(Vec3::ZERO, Vec3::new(0.08, 0.04, 0.01))
    }

    #[test]
    fn the_card_hangs_above_the_far_side_of_the_tray_facing_the_head() {
        for (yaw, scale, head) in [
            (0.0, 1.0, Vec3::new(0.0, 1.6, 0.0)),
            (0.7, 2.0, Vec3::new(0.5, 1.5, 0.3)),
            (-2.0, 0.5, Vec3::new(-0.4, 1.7, -1.2)),
        ] {
            let t = Tray {
                yaw,
                scale,
                ..tray()
            };
            let m = t.stage_from_sim() * panel_transform(&t, head, 0.5625);
            let centre = m.transform_point3(Vec3::ZERO);
            let right = m.transform_vector3(Vec3::X);
            let up = m.transform_vector3(Vec3::Y);
            let front = m.transform_vector3(Vec3::Z).normalize();
            // Physical size independent of the tray's magnification; upright.
            assert!((right.length() - PANEL_WIDTH).abs() < 1e-4, "{right}");
            assert!((up.length() - PANEL_WIDTH * 0.5625).abs() < 1e-4, "{up}");
            assert!(up.normalize().dot(Vec3::Y) > 0.9999, "{up}");
            assert!((centre.y - t.centre.y - PANEL_HEIGHT).abs() < 1e-4);
            // Facing the head horizontally, and beyond the tray centre as seen from it.
            let mut to_head = head - centre;
            to_head.y = 0.0;
            assert!(front.dot(to_head.normalize()) > 0.9999, "{front} {to_head}");
            let mut away = t.centre - head;
            away.y = 0.0;
            assert!((centre - t.centre).dot(away) > 0.0);
            // Seen from the head, image right is the viewer's right (not mirrored).
            let view_right = to_head.normalize().cross(Vec3::Y) * -1.0;
            assert!(
                right.normalize().dot(view_right) > 0.999,
                "{right} {view_right}"
            );
        }
    }
}
