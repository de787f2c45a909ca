//! Controller state per frame and the commands its button presses give (on the press,
//! not while held).

use glam::Vec2;

use super::pose::XrPose;

/// Trigger travel above which the blade counts as engaged.
pub const TRIGGER_ENGAGE: f32 = 0.5;
/// Squeeze travel above which the left grip moves the tray.
pub const SQUEEZE_GRAB: f32 = 0.5;

/// The controllers as sampled for one frame (poses in stage space at the predicted
/// display time; `None` while the controller is not tracked).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ControllerState {
    /// Right grip pose.
    pub right_grip: Option<XrPose>,
    /// Right trigger, 0..1.
    pub trigger: f32,
    /// A button.
    pub a: bool,
    /// B button.
    pub b: bool,
    /// Left grip pose.
    pub left_grip: Option<XrPose>,
    /// Left squeeze, 0..1.
    pub squeeze: f32,
    /// Left thumbstick, −1..1 each.
    pub stick: Vec2,
    /// Menu button.
    pub menu: bool,
}

impl ControllerState {
    /// Whether the blade is engaged (trigger past [`TRIGGER_ENGAGE`]).
    pub fn blade_engaged(&self) -> bool {
        self.trigger >= TRIGGER_ENGAGE
    }

    /// Whether the left grip is moving the tray.
    pub fn moving_tray(&self) -> bool {
        self.squeeze >= SQUEEZE_GRAB && self.left_grip.is_some()
    }
}

/// One-shot commands from button presses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Commands {
    /// A pressed: reset the scene.
    pub reset: bool,
    /// B pressed: toggle the stress overlay.
    pub toggle_stress: bool,
    /// Menu pressed: pause or resume.
    pub toggle_pause: bool,
}

/// The commands of the presses between `previous` and `now`.
pub fn commands(previous: &ControllerState, now: &ControllerState) -> Commands {
    Commands {
        reset: now.a && !previous.a,
        toggle_stress: now.b && !previous.b,
        toggle_pause: now.menu && !previous.menu,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presses_fire_once_and_thresholds_hold() {
        let up = ControllerState::default();
        let down = ControllerState {
            a: true,
            menu: true,
            trigger: 0.6,
            ..up
        };
        assert_eq!(
            commands(&up, &down),
            Commands {
                reset: true,
                toggle_stress: false,
                toggle_pause: true
            }
        );
        assert_eq!(commands(&down, &down), Commands::default());
        assert!(down.blade_engaged() && !up.blade_engaged());
        let no_pose = ControllerState { squeeze: 1.0, ..up };
        assert!(!no_pose.moving_tray());
        let grab = ControllerState {
            left_grip: Some(XrPose::default()),
            ..no_pose
        };
        assert!(grab.moving_tray());
    }
}
