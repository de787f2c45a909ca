//! Controller vibration per frame. The force → amplitude curve belongs to the scalpel
//! (incise-scalpel's `HapticCurve`); the app passes the amplitude in, and this turns it
//! into the pulse sent with `xrApplyHapticFeedback`.

/// Amplitudes below this are not sent (the Quest motors do not render them).
pub const MIN_AMPLITUDE: f32 = 0.02;
/// Vibration frequency requested, Hz (0 lets the runtime choose; Quest Touch: ~160 Hz).
pub const FREQUENCY_HZ: f32 = 0.0;

/// One vibration pulse (OpenXR `XrHapticVibration`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HapticPulse {
    /// Amplitude, 0..1.
    pub amplitude: f32,
    /// Duration, s.
    pub duration_s: f64,
    /// Frequency, Hz (0: the runtime's optimum).
    pub frequency_hz: f32,
}

/// The pulse for this frame: amplitude `amplitude` (0..1, NaN as 0) while the blade is
/// engaged, lasting one display period plus half (so consecutive frames overlap and the
/// motor does not stutter); `None` to stop the vibration.
pub fn haptic_pulse(amplitude: f32, engaged: bool, display_period_s: f64) -> Option<HapticPulse> {
    let a = if amplitude.is_nan() {
        0.0
    } else {
        amplitude.clamp(0.0, 1.0)
    };
    (engaged && a >= MIN_AMPLITUDE).then_some(HapticPulse {
        amplitude: a,
        duration_s: display_period_s * 1.5,
        frequency_hz: FREQUENCY_HZ,
    })
}

/// What to tell the controller this frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HapticCall {
    /// `xrApplyHapticFeedback` with this pulse.
    Apply(HapticPulse),
    /// `xrStopHapticFeedback`: the blade has just left the tissue.
    Stop,
    /// Nothing: the controller is already still.
    Nothing,
}

/// Whether the controller is vibrating: pulses are sent while the blade is in tissue and
/// one stop after it leaves, not a stop on every frame the blade is out.
#[derive(Debug, Clone, Copy, Default)]
pub struct HapticGate {
    vibrating: bool,
}

impl HapticGate {
    /// The call for this frame's pulse (`None`: no vibration wanted).
    pub fn next(&mut self, pulse: Option<HapticPulse>) -> HapticCall {
        match (pulse, self.vibrating) {
            (Some(p), _) => {
                self.vibrating = true;
                HapticCall::Apply(p)
            }
            (None, true) => {
                self.vibrating = false;
                HapticCall::Stop
            }
            (None, false) => HapticCall::Nothing,
        }
    }

    /// Make this frame's call for `pulse` through `vibrate` (the pulse, the one stop after
    /// the last, or nothing); the call made.
    pub fn send<E>(
        &mut self,
        pulse: Option<HapticPulse>,
        vibrate: impl FnOnce(Option<HapticPulse>) -> Result<(), E>,
    ) -> Result<HapticCall, E> {
        let call = self.next(pulse);
        match call {
            HapticCall::Apply(p) => vibrate(Some(p))?,
            HapticCall::Stop => vibrate(None)?,
            HapticCall::Nothing => {}
        }
        Ok(call)
    }

    /// Whether the last call left the controller vibrating (a stop is due at the end).
    pub fn vibrating(&self) -> bool {
        self.vibrating
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_stop_after_the_blade_leaves_and_none_while_it_is_out() {
        let mut g = HapticGate::default();
        let p = haptic_pulse(0.5, true, 0.01);
        let calls: Vec<HapticCall> = [None, None, p, p, None, None, None, p, None]
            .into_iter()
            .map(|x| g.next(x))
            .collect();
        let stops = calls.iter().filter(|c| **c == HapticCall::Stop).count();
        let applied = calls
            .iter()
            .filter(|c| matches!(c, HapticCall::Apply(_)))
            .count();
        assert_eq!((applied, stops), (3, 2), "{calls:?}");
        assert_eq!(calls[0], HapticCall::Nothing);
        assert_eq!(calls[4], HapticCall::Stop);
        assert_eq!(calls[5], HapticCall::Nothing);
        assert!(!g.vibrating());
        g.next(p);
        assert!(g.vibrating());
    }

    #[test]
    fn amplitude_passes_through_clamped_only_while_engaged() {
        let p = haptic_pulse(0.5, true, 1.0 / 72.0).unwrap();
        assert_eq!(p.amplitude, 0.5);
        assert!((p.duration_s - 1.5 / 72.0).abs() < 1e-12);
        assert_eq!(haptic_pulse(1.7, true, 0.01).unwrap().amplitude, 1.0);
        assert!(haptic_pulse(0.5, false, 0.01).is_none());
        assert!(haptic_pulse(0.01, true, 0.01).is_none());
        assert!(haptic_pulse(f32::NAN, true, 0.01).is_none());
    }
}
