//! The actions of the XR mode and their suggested bindings per interaction profile
//! (`xrSuggestInteractionProfileBindings`), as data the session turns into OpenXR calls.

/// One action of the XR mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// Right grip pose: the scalpel.
    ScalpelPose,
    /// Right trigger: the blade is engaged (no cutting while released).
    BladeEngaged,
    /// A: reset the scene.
    Reset,
    /// B: toggle the stress overlay.
    StressOverlay,
    /// Left grip pose: where the tray goes.
    TrayPose,
    /// Left squeeze: re-place the tray while held.
    MoveTray,
    /// Left thumbstick: x turns the tray, y scales it.
    TrayStick,
    /// Menu: pause/resume the simulation.
    Pause,
    /// Right haptic output (vibration).
    Haptics,
}

/// What kind of OpenXR action it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ActionKind {
    /// `XR_ACTION_TYPE_POSE_INPUT`.
    Pose,
    /// `XR_ACTION_TYPE_BOOLEAN_INPUT`.
    Button,
    /// `XR_ACTION_TYPE_FLOAT_INPUT` (a trigger or squeeze value, 0..1).
    Analog,
    /// `XR_ACTION_TYPE_VECTOR2F_INPUT`.
    Stick,
    /// `XR_ACTION_TYPE_VIBRATION_OUTPUT`.
    Vibration,
}

/// Every action: (action, OpenXR name, localized name, kind).
pub const ACTIONS: [(Action, &str, &str, ActionKind); 9] = [
    (
        Action::ScalpelPose,
        "scalpel_pose",
        "Scalpel (right hand)",
        ActionKind::Pose,
    ),
    (
        Action::BladeEngaged,
        "blade_engaged",
        "Engage blade",
        ActionKind::Analog,
    ),
    (
        Action::Reset,
        "reset_scene",
        "Reset scene",
        ActionKind::Button,
    ),
    (
        Action::StressOverlay,
        "stress_overlay",
        "Toggle stress overlay",
        ActionKind::Button,
    ),
    (
        Action::TrayPose,
        "tray_pose",
        "Tray (left hand)",
        ActionKind::Pose,
    ),
    (
        Action::MoveTray,
        "move_tray",
        "Move tray",
        ActionKind::Analog,
    ),
    (
        Action::TrayStick,
        "tray_stick",
        "Turn and scale tray",
        ActionKind::Stick,
    ),
    (Action::Pause, "pause", "Pause", ActionKind::Button),
    (
        Action::Haptics,
        "scalpel_haptics",
        "Scalpel vibration",
        ActionKind::Vibration,
    ),
];

/// Meta Quest Touch controllers (Quest 3 over Link reports this profile).
pub const OCULUS_TOUCH: &str = "/interaction_profiles/oculus/touch_controller";
/// The Khronos simple controller (any runtime): poses, select, menu, vibration.
pub const KHR_SIMPLE: &str = "/interaction_profiles/khr/simple_controller";

/// Suggested bindings: (profile, [(action, input/output path)]).
pub const BINDINGS: [(&str, &[(Action, &str)]); 2] = [
    (
        OCULUS_TOUCH,
        &[
            (Action::ScalpelPose, "/user/hand/right/input/grip/pose"),
            (Action::BladeEngaged, "/user/hand/right/input/trigger/value"),
            (Action::Reset, "/user/hand/right/input/a/click"),
            (Action::StressOverlay, "/user/hand/right/input/b/click"),
            (Action::TrayPose, "/user/hand/left/input/grip/pose"),
            (Action::MoveTray, "/user/hand/left/input/squeeze/value"),
            (Action::TrayStick, "/user/hand/left/input/thumbstick"),
            (Action::Pause, "/user/hand/left/input/menu/click"),
            (Action::Haptics, "/user/hand/right/output/haptic"),
        ],
    ),
    (
        KHR_SIMPLE,
        &[
            (Action::ScalpelPose, "/user/hand/right/input/grip/pose"),
            (Action::BladeEngaged, "/user/hand/right/input/select/click"),
            (Action::TrayPose, "/user/hand/left/input/grip/pose"),
            (Action::MoveTray, "/user/hand/left/input/select/click"),
            (Action::Pause, "/user/hand/left/input/menu/click"),
            (Action::Haptics, "/user/hand/right/output/haptic"),
        ],
    ),
];

/// The action's OpenXR name and kind.
pub fn describe(action: Action) -> (&'static str, &'static str, ActionKind) {
    let (_, name, local, kind) = ACTIONS
        .iter()
        .find(|(a, ..)| *a == action)
        .copied()
        .expect("every Action is listed in ACTIONS");
    (name, local, kind)
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use super::*;

    #[test]
    fn every_action_is_bound_on_touch_and_the_essentials_on_the_simple_controller() {
        let touch: HashSet<Action> = BINDINGS[0].1.iter().map(|(a, _)| *a).collect();
        assert_eq!(touch.len(), ACTIONS.len(), "Touch binds every action once");
        let simple: HashSet<Action> = BINDINGS[1].1.iter().map(|(a, _)| *a).collect();
        for a in [
            Action::ScalpelPose,
            Action::BladeEngaged,
            Action::Pause,
            Action::Haptics,
        ] {
            assert!(simple.contains(&a), "{a:?}");
        }
        // Names are OpenXR-legal (lower case, digits, -_.) and unique.
        let names: HashSet<&str> = ACTIONS.iter().map(|a| a.1).collect();
        assert_eq!(names.len(), ACTIONS.len());
        for n in &names {
            assert!(
                n.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || "-_.".contains(c))
            );
        }
    }

    #[test]
    fn paths_match_their_action_kinds_and_hands() {
        for (profile, binds) in BINDINGS {
            assert!(profile.starts_with("/interaction_profiles/"));
            for (action, path) in binds {
                let (_, _, kind) = describe(*action);
                let ok = match kind {
                    ActionKind::Pose => path.ends_with("/pose"),
                    ActionKind::Button => path.ends_with("/click"),
                    ActionKind::Analog => path.ends_with("/value") || path.ends_with("/click"),
                    ActionKind::Stick => path.ends_with("/thumbstick"),
                    ActionKind::Vibration => path.ends_with("/output/haptic"),
                };
                assert!(ok, "{profile}: {action:?} → {path}");
                let right = matches!(
                    action,
                    Action::ScalpelPose
                        | Action::BladeEngaged
                        | Action::Reset
                        | Action::StressOverlay
                        | Action::Haptics
                );
                let hand = if right {
                    "/user/hand/right/"
                } else {
                    "/user/hand/left/"
                };
                assert!(path.starts_with(hand), "{profile}: {action:?} → {path}");
            }
        }
    }
}
