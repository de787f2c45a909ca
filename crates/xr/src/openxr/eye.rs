//! One eye's view and projection from the pose and field of view OpenXR reports for it
//! (`xrLocateViews`), in the simulation's world through the tray placement.

use glam::{Mat4, Vec4};

use super::pose::{Fov, XrPose};
use crate::camera::View;

/// The eyes of a stereo view configuration, in the order OpenXR reports them
/// (`XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO`: view 0 is the left eye) and the order of
/// the swapchain's array layers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Eye {
    /// View 0, array layer 0.
    Left,
    /// View 1, array layer 1.
    Right,
}

/// Both eyes in view order.
pub const EYE_ORDER: [Eye; 2] = [Eye::Left, Eye::Right];

impl Eye {
    /// The view index and swapchain array layer of this eye.
    pub fn index(self) -> usize {
        match self {
            Eye::Left => 0,
            Eye::Right => 1,
        }
    }
}

/// Near clip plane of the headset views, m (closer than a hand-held scalpel gets).
pub const NEAR: f32 = 0.02;
/// Far clip plane of the headset views, m.
pub const FAR: f32 = 50.0;

/// The view → clip matrix of an asymmetric field of view for wgpu's clip space (x, y in
/// −1..1 with y up, depth 0 at `near` to 1 at `far`), right-handed view space looking
/// down −z. With `l, r, u, d` the tangents of the four angles:
/// `x_ndc = (2·x/(−z) − (r + l)) / (r − l)`, `y_ndc = (2·y/(−z) − (u + d)) / (u − d)`.
pub fn projection(fov: Fov, near: f32, far: f32) -> Mat4 {
    let (l, r) = (fov.left.tan(), fov.right.tan());
    let (u, d) = (fov.up.tan(), fov.down.tan());
    let (w, h) = (r - l, u - d);
    Mat4::from_cols(
        Vec4::new(2.0 / w, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 / h, 0.0, 0.0),
        Vec4::new((r + l) / w, (u + d) / h, far / (near - far), -1.0),
        Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
    )
}

/// The renderer's view of one eye at `pose` (stage space) with `fov`, looking at the
/// simulation world placed in the stage by `stage_from_sim` (see `Tray`).
pub fn eye_view(pose: XrPose, fov: Fov, stage_from_sim: Mat4) -> View {
    View {
        view: pose.matrix().inverse() * stage_from_sim,
        proj: projection(fov, NEAR, FAR),
    }
}

#[cfg(test)]
mod tests {
    use glam::camera::rh::proj::directx;
    use glam::{Quat, Vec2, Vec3};

    use super::*;

    fn close(a: Mat4, b: Mat4) -> bool {
        a.abs_diff_eq(b, 1e-5)
    }

    #[test]
    fn an_asymmetric_fov_gives_the_hand_computed_matrix() {
        // tan 45° = 1 on the right, tan(−26.565°) = −0.5 on the left, up 0.75, down −0.25.
        let fov = Fov {
            left: (-0.5f32).atan(),
            right: 1f32.atan(),
            up: 0.75f32.atan(),
            down: (-0.25f32).atan(),
        };
        let (n, f) = (0.1, 100.0);
        let p = projection(fov, n, f);
        // r − l = 1.5, r + l = 0.5, u − d = 1.0, u + d = 0.5.
        let expected = Mat4::from_cols_array_2d(&[
            [2.0 / 1.5, 0.0, 0.0, 0.0],
            [0.0, 2.0, 0.0, 0.0],
            [0.5 / 1.5, 0.5, f / (n - f), -1.0],
            [0.0, 0.0, n * f / (n - f), 0.0],
        ]);
        assert!(close(p, expected), "{p}\n{expected}");
        // The frustum's sides land on the clip edges, near on depth 0 and far on depth 1.
        let ndc = |v: Vec3| p.project_point3(v);
        assert!((ndc(Vec3::new(1.0, 0.0, -1.0)).x - 1.0).abs() < 1e-5);
        assert!((ndc(Vec3::new(-0.5, 0.0, -1.0)).x + 1.0).abs() < 1e-5);
        assert!((ndc(Vec3::new(0.0, 0.75, -1.0)).y - 1.0).abs() < 1e-5);
        assert!((ndc(Vec3::new(0.0, -0.25, -1.0)).y + 1.0).abs() < 1e-5);
        assert!(ndc(Vec3::new(0.0, 0.0, -n)).z.abs() < 1e-5);
        assert!((ndc(Vec3::new(0.0, 0.0, -f)).z - 1.0).abs() < 1e-4);
    }

    #[test]
    fn a_symmetric_fov_matches_the_desktop_perspective() {
        let fov = Fov::symmetric(90f32.to_radians(), 60f32.to_radians());
        let aspect = 1.0 / 30f32.to_radians().tan();
        let desk = directx::perspective(60f32.to_radians(), aspect, NEAR, FAR);
        assert!(close(projection(fov, NEAR, FAR), desk));
    }

    #[test]
    fn eyes_come_left_then_right_and_see_a_point_with_the_expected_disparity() {
        assert_eq!(EYE_ORDER.map(Eye::index), [0, 1]);
        // Eyes 64 mm apart at 1.6 m, looking down −z at a point 0.5 m ahead, identity tray.
        let ipd = 0.064;
        let fov = Fov::symmetric(90f32.to_radians(), 90f32.to_radians());
        let views = EYE_ORDER.map(|e| {
            let x = if e == Eye::Left {
                -ipd / 2.0
            } else {
                ipd / 2.0
            };
            eye_view(
                XrPose::new(Vec3::new(x, 1.6, 0.0), Quat::IDENTITY),
                fov,
                Mat4::IDENTITY,
            )
        });
        let size = Vec2::new(1000.0, 1000.0);
        let p = Vec3::new(0.0, 1.6, -0.5);
        let l = views[0].project(p, size).unwrap();
        let r = views[1].project(p, size).unwrap();
        // Focal length 500 px (tan 45° = 1): disparity = f·ipd/z = 500·0.064/0.5 = 64 px,
        // the point further right in the left eye.
        assert!((l.x - r.x - 64.0).abs() < 1e-2, "{l} {r}");
        assert!((l.y - r.y).abs() < 1e-3);
        assert!((views[0].eye() - Vec3::new(-0.032, 1.6, 0.0)).length() < 1e-5);
    }
}
