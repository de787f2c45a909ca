//! Contact force → controller vibration amplitude (0..1, as OpenXR's
//! `XrHapticVibration.amplitude` and the Quest controllers take it).
//!
//! `a(f) = 0` below the perception threshold `f0`, `1` at and above saturation `f1`, and
//! `((f − f0) / (f1 − f0))^γ` between: continuous and monotone. With `γ < 1` the curve is
//! compressive, spending more of the amplitude range on small forces: force
//! discrimination is roughly Weber-like (just-noticeable difference ≈ 7 % of the
//! reference over 2.5–10 N, Pang, Tan & Durlach 1991, "Manual discrimination of force
//! using active finger motion", Percept. Psychophys. 49(6); review: Bergmann Tiest &
//! Kappers 2015, "Haptic perception of force", Scholarpedia 10(4):32732), so a change of
//! 0.1 N matters near contact onset and not at 4 N.

use serde::{Deserialize, Serialize};

use crate::error::FieldError;

/// The force → amplitude curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HapticCurve {
    /// Forces below this give no vibration, N.
    pub threshold: f32,
    /// Forces at or above this give full amplitude, N.
    pub saturation: f32,
    /// Shape exponent γ (> 0; < 1 compressive).
    pub exponent: f32,
}

impl Default for HapticCurve {
    /// Nominal values, not fitted: threshold 0.05 N (below it the contact force is mostly
    /// solver noise from resting contact), saturation 4 N (the order of a scalpel skin
    /// incision force), γ = 0.5.
    fn default() -> Self {
        HapticCurve {
            threshold: 0.05,
            saturation: 4.0,
            exponent: 0.5,
        }
    }
}

impl HapticCurve {
    /// Ok, or the first field out of range.
    pub fn validate(&self) -> Result<(), FieldError> {
        if !(self.threshold.is_finite() && self.threshold >= 0.0) {
            return Err(FieldError::new(
                "threshold",
                format!("must be a finite force >= 0 N, got {}", self.threshold),
            ));
        }
        if !(self.saturation.is_finite() && self.saturation > self.threshold) {
            return Err(FieldError::new(
                "saturation",
                format!(
                    "must be a finite force above the threshold ({} N), got {}",
                    self.threshold, self.saturation
                ),
            ));
        }
        if !(self.exponent.is_finite() && self.exponent > 0.0) {
            return Err(FieldError::new(
                "exponent",
                format!("must be a finite number > 0, got {}", self.exponent),
            ));
        }
        Ok(())
    }

    /// Vibration amplitude in [0, 1] for a contact force magnitude `force` (N); NaN and
    /// negative forces give 0.
    pub fn amplitude(&self, force: f32) -> f32 {
        if force.is_nan() || force <= self.threshold {
            return 0.0;
        }
        if force >= self.saturation {
            return 1.0;
        }
        let x = (force - self.threshold) / (self.saturation - self.threshold);
        x.clamp(0.0, 1.0).powf(self.exponent).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_below_one_above_monotone_and_continuous() {
        let c = HapticCurve::default();
        c.validate().unwrap();
        assert_eq!(c.amplitude(0.0), 0.0);
        assert_eq!(c.amplitude(0.049), 0.0);
        assert_eq!(c.amplitude(c.threshold), 0.0);
        assert_eq!(c.amplitude(c.saturation), 1.0);
        assert_eq!(c.amplitude(100.0), 1.0);
        assert_eq!(c.amplitude(f32::INFINITY), 1.0);
        let mut prev = 0.0;
        let n = 100_000;
        for i in 0..=n {
            let f = 5.0 * i as f32 / n as f32;
            let a = c.amplitude(f);
            assert!((0.0..=1.0).contains(&a));
            assert!(a >= prev, "not monotone at {f} N");
            // Continuity: with γ = 0.5 the steepest step of this grid is at the threshold,
            // √(5e-5 / 3.95) ≈ 0.0036.
            assert!(a - prev < 0.005, "jump of {} at {f} N", a - prev);
            prev = a;
        }
    }

    #[test]
    fn nan_and_negative_forces_give_zero() {
        let c = HapticCurve::default();
        assert_eq!(c.amplitude(f32::NAN), 0.0);
        assert_eq!(c.amplitude(-1.0), 0.0);
        assert_eq!(c.amplitude(f32::NEG_INFINITY), 0.0);
    }

    #[test]
    fn linear_exponent_is_a_ramp() {
        let c = HapticCurve {
            threshold: 1.0,
            saturation: 3.0,
            exponent: 1.0,
        };
        assert!((c.amplitude(2.0) - 0.5).abs() < 1e-6);
        let bad = HapticCurve {
            saturation: 0.5,
            ..c
        };
        assert_eq!(bad.validate().unwrap_err().field, "saturation");
    }
}
