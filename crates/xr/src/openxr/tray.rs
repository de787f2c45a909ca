//! The virtual tray the organ lies on: where it stands in the room (stage space), how it
//! is turned and scaled, and how the left controller moves it.

use glam::{Mat4, Quat, Vec2, Vec3};

use super::pose::{XrPose, stage_from_sim_axes};

/// Default height of the tray surface above the stage floor, m (a table).
pub const TABLE_HEIGHT: f32 = 0.9;
/// Default distance of the tray in front of the stage origin, m.
pub const TABLE_DISTANCE: f32 = 0.45;
/// Tray turn rate at full left-stick deflection, rad/s.
pub const TURN_RATE: f32 = std::f32::consts::FRAC_PI_2;
/// Scale change at full left-stick deflection: this factor per second.
pub const SCALE_RATE: f32 = 2.0;
/// Smallest and largest tray scale.
pub const SCALE_RANGE: (f32, f32) = (0.25, 4.0);
/// Stick deflections smaller than this are ignored (controller drift).
pub const STICK_DEAD_ZONE: f32 = 0.15;

/// The tray's placement: the simulation point `anchor` (the organ's rest footprint
/// centre) sits at `centre` in the stage, turned by `yaw` about stage +y and scaled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tray {
    /// Tray surface centre in stage space, m.
    pub centre: Vec3,
    /// Turn about stage +y, radians.
    pub yaw: f32,
    /// Magnification of the organ (1: life size).
    pub scale: f32,
    /// The simulation point placed on `centre`, m (sim world).
    pub anchor: Vec3,
}

impl Tray {
    /// A life-size tray at table height in front of the stage origin for an organ whose
    /// rest bounds are `[lo, hi]` (sim world): the centre of its bottom face on the tray.
    pub fn for_bounds(lo: Vec3, hi: Vec3) -> Self {
        let c = (lo + hi) * 0.5;
        Tray {
            centre: Vec3::new(0.0, TABLE_HEIGHT, -TABLE_DISTANCE),
            yaw: 0.0,
            scale: 1.0,
            anchor: Vec3::new(c.x, c.y, lo.z),
        }
    }

    /// Sim world → stage: `T(centre) · R_y(yaw) · S(scale) · axes · T(−anchor)`.
    pub fn stage_from_sim(&self) -> Mat4 {
        Mat4::from_translation(self.centre)
            * Mat4::from_rotation_y(self.yaw)
            * Mat4::from_scale(Vec3::splat(self.scale))
            * Mat4::from_mat3(stage_from_sim_axes())
            * Mat4::from_translation(-self.anchor)
    }

    /// Stage → sim world.
    pub fn sim_from_stage(&self) -> Mat4 {
        self.stage_from_sim().inverse()
    }

    /// The rotation part of sim → stage (no scale).
    pub fn stage_from_sim_rotation(&self) -> Quat {
        Quat::from_rotation_y(self.yaw) * Quat::from_mat3(&stage_from_sim_axes())
    }

    /// The tray moved to the left grip `grip`: centre at the grip, turned so the organ's
    /// far side (sim +y) points where the controller points, projected on the floor.
    /// A controller pointing straight up or down keeps the current turn.
    pub fn placed_at(&self, grip: XrPose) -> Tray {
        let forward = grip.orientation * -Vec3::Z;
        let flat = Vec2::new(forward.x, forward.z);
        let yaw = if flat.length() > 1e-3 {
            // R_y(yaw) takes −z to (−sin yaw, 0, −cos yaw).
            (-flat.x).atan2(-flat.y)
        } else {
            self.yaw
        };
        Tray {
            centre: grip.position,
            yaw,
            ..*self
        }
    }

    /// The tray after `dt` seconds of left-stick deflection `stick` (x turns, y scales;
    /// each in −1..1, dead zone applied), scale kept in [`SCALE_RANGE`].
    pub fn steered(&self, stick: Vec2, dt: f32) -> Tray {
        let dz = |v: f32| {
            if v.abs() < STICK_DEAD_ZONE {
                0.0
            } else {
                v.clamp(-1.0, 1.0)
            }
        };
        let (sx, sy) = (dz(stick.x), dz(stick.y));
        Tray {
            // Stick right turns the tray clockwise seen from above (negative about +y).
            yaw: self.yaw - sx * TURN_RATE * dt,
            scale: (self.scale * SCALE_RATE.powf(sy * dt)).clamp(SCALE_RANGE.0, SCALE_RANGE.1),
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::FRAC_PI_2;

    use super::*;

    #[test]
    fn the_organ_footprint_lands_on_the_table_in_front_of_the_user() {
        let tray = Tray::for_bounds(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.08, 0.04, 0.02));
        assert_eq!(tray.anchor, Vec3::new(0.04, 0.02, 0.0));
        let m = tray.stage_from_sim();
        let bottom = m.transform_point3(tray.anchor);
        assert!((bottom - Vec3::new(0.0, 0.9, -0.45)).length() < 1e-6);
        // The top of the organ is 2 cm above the table; sim +y runs away from the user.
        let top = m.transform_point3(Vec3::new(0.04, 0.02, 0.02));
        assert!((top - Vec3::new(0.0, 0.92, -0.45)).length() < 1e-6, "{top}");
        let far = m.transform_point3(Vec3::new(0.04, 0.04, 0.0));
        assert!((far - Vec3::new(0.0, 0.9, -0.47)).length() < 1e-6, "{far}");
        assert!(
            tray.sim_from_stage()
                .transform_point3(bottom)
                .abs_diff_eq(tray.anchor, 1e-6)
        );
    }

    #[test]
    fn turning_and_scaling_by_hand_computed_amounts() {
        let mut tray = Tray::for_bounds(Vec3::ZERO, Vec3::new(0.1, 0.1, 0.1));
        tray.yaw = FRAC_PI_2;
        tray.scale = 2.0;
        // sim +x (0.1 m from the anchor) → scaled 0.2 m → turned 90° about +y: −z.
        let p = tray
            .stage_from_sim()
            .transform_point3(tray.anchor + Vec3::new(0.1, 0.0, 0.0));
        assert!(
            (p - (tray.centre + Vec3::new(0.0, 0.0, -0.2))).length() < 1e-6,
            "{p}"
        );
        let q = tray.stage_from_sim_rotation();
        assert!((q * Vec3::X - -Vec3::Z).length() < 1e-6);
        assert!((q * Vec3::Z - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn the_left_grip_replaces_the_tray_facing_where_the_controller_points() {
        let tray = Tray::for_bounds(Vec3::ZERO, Vec3::ONE * 0.1);
        // Controller at (0.3, 1.0, −0.2) pointing along −x (90° about +y).
        let grip = XrPose::new(Vec3::new(0.3, 1.0, -0.2), Quat::from_rotation_y(FRAC_PI_2));
        let moved = tray.placed_at(grip);
        assert_eq!(moved.centre, grip.position);
        assert!((moved.yaw - FRAC_PI_2).abs() < 1e-6);
        assert_eq!(moved.scale, tray.scale);
        // Sim +y (away from the user) now points along the controller: −x.
        let d = moved.stage_from_sim().transform_vector3(Vec3::Y);
        assert!((d - -Vec3::X).length() < 1e-6, "{d}");
        // Pointing straight down keeps the turn.
        let down = XrPose::new(Vec3::ZERO, Quat::from_rotation_x(-FRAC_PI_2));
        assert_eq!(moved.placed_at(down).yaw, moved.yaw);
    }

    #[test]
    fn the_left_stick_turns_and_scales_within_limits() {
        let tray = Tray::for_bounds(Vec3::ZERO, Vec3::ONE);
        // Full right for 1 s: −90°. Full up for 1 s: ×2. Drift inside the dead zone: nothing.
        let t = tray.steered(Vec2::new(1.0, 0.0), 1.0);
        assert!((t.yaw + FRAC_PI_2).abs() < 1e-6);
        let t = tray.steered(Vec2::new(0.0, 1.0), 1.0);
        assert!((t.scale - 2.0).abs() < 1e-6);
        assert_eq!(tray.steered(Vec2::new(0.1, -0.1), 1.0), tray);
        let mut big = tray;
        for _ in 0..100 {
            big = big.steered(Vec2::new(0.0, 1.0), 1.0);
        }
        assert_eq!(big.scale, SCALE_RANGE.1);
    }
}
