//! Poses and fields of view as OpenXR reports them, and the fixed change of axes between
//! OpenXR's stage space (+y up, −z forward) and the simulation's world (+z up).

use glam::{Mat3, Mat4, Quat, Vec3};

/// A rigid pose in stage space (OpenXR `XrPosef`): position, m, and orientation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct XrPose {
    /// Position, m.
    pub position: Vec3,
    /// Orientation (unit quaternion).
    pub orientation: Quat,
}

impl XrPose {
    /// A pose from its position and orientation.
    pub fn new(position: Vec3, orientation: Quat) -> Self {
        XrPose {
            position,
            orientation,
        }
    }

    /// The pose as a matrix: its own frame → stage.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_rotation_translation(self.orientation, self.position)
    }
}

/// A view's field of view (OpenXR `XrFovf`): the angles of its four sides from the view
/// axis, radians; `left` and `down` are negative for a view that contains its axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fov {
    /// Angle of the left side (negative to the left).
    pub left: f32,
    /// Angle of the right side.
    pub right: f32,
    /// Angle of the top side.
    pub up: f32,
    /// Angle of the bottom side (negative below).
    pub down: f32,
}

impl Fov {
    /// A symmetric field of view of `horizontal` × `vertical` total angle, radians.
    pub fn symmetric(horizontal: f32, vertical: f32) -> Self {
        Fov {
            left: -horizontal * 0.5,
            right: horizontal * 0.5,
            up: vertical * 0.5,
            down: -vertical * 0.5,
        }
    }
}

/// Stage axes of the simulation's axes: sim +x → stage +x, sim +y → stage −z (away from
/// the user), sim +z (up) → stage +y (up). A proper rotation (determinant +1).
pub fn stage_from_sim_axes() -> Mat3 {
    Mat3::from_cols(Vec3::X, -Vec3::Z, Vec3::Y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axis_change_is_a_rotation_taking_sim_up_to_stage_up() {
        let m = stage_from_sim_axes();
        assert!((m.determinant() - 1.0).abs() < 1e-6);
        assert_eq!(m * Vec3::Z, Vec3::Y);
        assert_eq!(m * Vec3::Y, -Vec3::Z);
        assert_eq!(m * Vec3::X, Vec3::X);
    }

    #[test]
    fn a_pose_matrix_moves_its_origin_to_its_position() {
        let p = XrPose::new(
            Vec3::new(1.0, 2.0, 3.0),
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        );
        let m = p.matrix();
        assert_eq!(m.transform_point3(Vec3::ZERO), p.position);
        // 90° about +y takes −z (forward) to −x.
        let f = m.transform_vector3(-Vec3::Z);
        assert!((f - -Vec3::X).length() < 1e-6, "{f}");
    }
}
