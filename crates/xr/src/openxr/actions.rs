//! The XR mode's OpenXR actions: created from the [`super::bindings`] tables, suggested
//! for each interaction profile, attached to the session, and sampled every frame into a
//! [`ControllerState`].

use ::openxr as xr;
use glam::{Quat, Vec2, Vec3};

use super::bindings::{Action, BINDINGS, describe};
use super::controls::ControllerState;
use super::error::{XrError, xr_call};
use super::haptics::HapticPulse;
use super::pose::XrPose;

/// The action set, its actions and the two grip spaces.
pub struct XrActions {
    set: xr::ActionSet,
    scalpel_pose: xr::Action<xr::Posef>,
    blade: xr::Action<f32>,
    reset: xr::Action<bool>,
    stress: xr::Action<bool>,
    tray_pose: xr::Action<xr::Posef>,
    move_tray: xr::Action<f32>,
    stick: xr::Action<xr::Vector2f>,
    pause: xr::Action<bool>,
    haptics: xr::Action<xr::Haptic>,
    right_space: xr::Space,
    left_space: xr::Space,
}

fn make<T: xr::ActionTy>(set: &xr::ActionSet, a: Action) -> Result<xr::Action<T>, XrError> {
    let (name, local, _) = describe(a);
    set.create_action::<T>(name, local, &[])
        .map_err(xr_call("xrCreateAction"))
}

impl XrActions {
    /// Create the actions, suggest every profile's bindings and attach them to `session`.
    pub fn new(
        instance: &xr::Instance,
        session: &xr::Session<xr::Vulkan>,
    ) -> Result<Self, XrError> {
        let set = instance
            .create_action_set("incise", "incise scalpel", 0)
            .map_err(xr_call("xrCreateActionSet"))?;
        let scalpel_pose = make(&set, Action::ScalpelPose)?;
        let blade = make(&set, Action::BladeEngaged)?;
        let reset = make(&set, Action::Reset)?;
        let stress = make(&set, Action::StressOverlay)?;
        let tray_pose = make(&set, Action::TrayPose)?;
        let move_tray = make(&set, Action::MoveTray)?;
        let stick = make(&set, Action::TrayStick)?;
        let pause = make(&set, Action::Pause)?;
        let haptics = make(&set, Action::Haptics)?;
        let actions = XrActions {
            right_space: scalpel_pose
                .create_space(session, xr::Path::NULL, xr::Posef::IDENTITY)
                .map_err(xr_call("xrCreateActionSpace"))?,
            left_space: tray_pose
                .create_space(session, xr::Path::NULL, xr::Posef::IDENTITY)
                .map_err(xr_call("xrCreateActionSpace"))?,
            set,
            scalpel_pose,
            blade,
            reset,
            stress,
            tray_pose,
            move_tray,
            stick,
            pause,
            haptics,
        };
        for (profile, binds) in BINDINGS {
            let path = instance
                .string_to_path(profile)
                .map_err(xr_call("xrStringToPath"))?;
            let mut suggested = Vec::with_capacity(binds.len());
            for (action, p) in binds {
                let p = instance
                    .string_to_path(p)
                    .map_err(xr_call("xrStringToPath"))?;
                suggested.push(actions.binding(*action, p));
            }
            instance
                .suggest_interaction_profile_bindings(path, &suggested)
                .map_err(xr_call("xrSuggestInteractionProfileBindings"))?;
        }
        session
            .attach_action_sets(&[&actions.set])
            .map_err(xr_call("xrAttachSessionActionSets"))?;
        Ok(actions)
    }

    fn binding(&self, action: Action, path: xr::Path) -> xr::Binding<'_> {
        match action {
            Action::ScalpelPose => xr::Binding::new(&self.scalpel_pose, path),
            Action::BladeEngaged => xr::Binding::new(&self.blade, path),
            Action::Reset => xr::Binding::new(&self.reset, path),
            Action::StressOverlay => xr::Binding::new(&self.stress, path),
            Action::TrayPose => xr::Binding::new(&self.tray_pose, path),
            Action::MoveTray => xr::Binding::new(&self.move_tray, path),
            Action::TrayStick => xr::Binding::new(&self.stick, path),
            Action::Pause => xr::Binding::new(&self.pause, path),
            Action::Haptics => xr::Binding::new(&self.haptics, path),
        }
    }

    /// Sync the actions and read the controllers at `time` in `stage` space.
    pub fn sample(
        &self,
        session: &xr::Session<xr::Vulkan>,
        stage: &xr::Space,
        time: xr::Time,
    ) -> Result<ControllerState, XrError> {
        session
            .sync_actions(&[xr::ActiveActionSet::new(&self.set)])
            .map_err(xr_call("xrSyncActions"))?;
        let pose = |space: &xr::Space| -> Result<Option<XrPose>, XrError> {
            let loc = space
                .locate(stage, time)
                .map_err(xr_call("xrLocateSpace"))?;
            let valid =
                xr::SpaceLocationFlags::POSITION_VALID | xr::SpaceLocationFlags::ORIENTATION_VALID;
            Ok(loc
                .location_flags
                .contains(valid)
                .then(|| to_pose(loc.pose)))
        };
        let f = |a: &xr::Action<f32>| {
            a.state(session, xr::Path::NULL)
                .map(|s| if s.is_active { s.current_state } else { 0.0 })
        };
        let b = |a: &xr::Action<bool>| {
            a.state(session, xr::Path::NULL)
                .map(|s| s.is_active && s.current_state)
        };
        let stick = self
            .stick
            .state(session, xr::Path::NULL)
            .map_err(xr_call("xrGetActionStateVector2f"))?;
        Ok(ControllerState {
            right_grip: pose(&self.right_space)?,
            trigger: f(&self.blade).map_err(xr_call("xrGetActionStateFloat"))?,
            a: b(&self.reset).map_err(xr_call("xrGetActionStateBoolean"))?,
            b: b(&self.stress).map_err(xr_call("xrGetActionStateBoolean"))?,
            left_grip: pose(&self.left_space)?,
            squeeze: f(&self.move_tray).map_err(xr_call("xrGetActionStateFloat"))?,
            stick: if stick.is_active {
                Vec2::new(stick.current_state.x, stick.current_state.y)
            } else {
                Vec2::ZERO
            },
            menu: b(&self.pause).map_err(xr_call("xrGetActionStateBoolean"))?,
        })
    }

    /// Vibrate the right controller (`xrApplyHapticFeedback`) or stop it.
    pub fn vibrate(
        &self,
        session: &xr::Session<xr::Vulkan>,
        pulse: Option<HapticPulse>,
    ) -> Result<(), XrError> {
        match pulse {
            Some(p) => {
                let event = xr::HapticVibration::new()
                    .amplitude(p.amplitude)
                    .duration(xr::Duration::from_nanos((p.duration_s * 1e9) as i64))
                    .frequency(p.frequency_hz);
                self.haptics
                    .apply_feedback(session, xr::Path::NULL, &event)
                    .map_err(xr_call("xrApplyHapticFeedback"))
            }
            None => self
                .haptics
                .stop_feedback(session, xr::Path::NULL)
                .map_err(xr_call("xrStopHapticFeedback")),
        }
    }
}

/// An OpenXR pose as an [`XrPose`].
pub fn to_pose(p: xr::Posef) -> XrPose {
    XrPose {
        position: Vec3::new(p.position.x, p.position.y, p.position.z),
        orientation: Quat::from_xyzw(
            p.orientation.x,
            p.orientation.y,
            p.orientation.z,
            p.orientation.w,
        )
        .normalize(),
    }
}
