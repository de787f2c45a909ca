//! The series damper c2 of the three-element element: linear, or force-dependent so that a
//! plastic or rheological body keeps its shape under weak loads such as gravity
//! (PHYSICS.md §3, "Force-dependent damper"; seed 002 §6, eq. (7)).

use serde::{Deserialize, Serialize};

/// The series damper's viscosity law.
///
/// In an [`ElementParams`](super::ElementParams) the coefficients are N·s/m and the
/// thresholds N; in a [`RheologyMaterial`](super::RheologyMaterial) they are per unit
/// length and area (Pa·s and Pa) and [`Damper::for_edge`] scales them to one edge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Damper {
    /// A constant coefficient c2, N·s/m (Pa·s in a material).
    Linear(f64),
    /// `c2 = c_max` for `|f| ≤ f1`, `c_min` for `|f| ≥ f2`, `c_max·exp(−B(|f| − f1))` between.
    ForceDependent {
        /// Coefficient under weak forces, N·s/m (Pa·s in a material).
        c_max: f64,
        /// Coefficient under strong forces, N·s/m (Pa·s in a material).
        c_min: f64,
        /// Force up to which the damper is at `c_max`, N (Pa in a material).
        f1: f64,
        /// Force from which the damper is at `c_min`, N (Pa in a material).
        f2: f64,
    },
}

/// Iterations of the safeguarded Newton solve for a force-consistent coefficient.
const MAX_ITERATIONS: usize = 60;

impl Damper {
    /// The coefficient c2 at a carried force of magnitude `force_abs` (N).
    // PHYSICS.md §3, force-dependent damper [reconstructed]:
    // c2 = c_max·exp(−B(|f| − f1)) for f1 < |f| < f2, B = ln(c_max/c_min)/(f2 − f1).
    pub fn coefficient(&self, force_abs: f64) -> f64 {
        match *self {
            Damper::Linear(c) => c,
            Damper::ForceDependent {
                c_max,
                c_min,
                f1,
                f2,
            } => {
                if force_abs <= f1 {
                    c_max
                } else if force_abs >= f2 {
                    c_min
                } else {
                    let b = (c_max / c_min).ln() / (f2 - f1);
                    c_max * (-b * (force_abs - f1)).exp()
                }
            }
        }
    }

    /// This damper for an edge of rest length `l0` (m): viscosities × l0, forces × l0².
    #[inline]
    pub fn for_edge(&self, l0: f64) -> Damper {
        match *self {
            Damper::Linear(eta) => Damper::Linear(eta * l0),
            Damper::ForceDependent {
                c_max,
                c_min,
                f1,
                f2,
            } => Damper::ForceDependent {
                c_max: c_max * l0,
                c_min: c_min * l0,
                f1: f1 * l0 * l0,
                f2: f2 * l0 * l0,
            },
        }
    }

    /// The largest coefficient the damper can take, N·s/m.
    pub fn max_coefficient(&self) -> f64 {
        match *self {
            Damper::Linear(c) => c,
            Damper::ForceDependent { c_max, .. } => c_max,
        }
    }

    /// The smallest coefficient the damper can take, N·s/m.
    pub fn min_coefficient(&self) -> f64 {
        match *self {
            Damper::Linear(c) => c,
            Damper::ForceDependent { c_min, .. } => c_min,
        }
    }

    /// The coefficient that agrees with the force it carries: the root of `c = c2(φ(c))`.
    ///
    /// `carried(c)` returns `(φ, dφ/dc)`, the magnitude of the damper's force if its
    /// coefficient were `c`, which must not decrease with `c`. Because `c2(·)` does not
    /// increase with the force, `c − c2(φ(c))` increases with `c` and the root in
    /// `[c_min, c_max]` is unique: the element law stays single-valued although the
    /// damper's coefficient depends on its own force.
    pub fn consistent_coefficient(&self, carried: impl Fn(f64) -> (f64, f64)) -> f64 {
        let Damper::ForceDependent {
            c_max,
            c_min,
            f1,
            f2,
        } = *self
        else {
            return self.max_coefficient();
        };
        let at_max = carried(c_max).0;
        if at_max <= f1 {
            return c_max;
        }
        if carried(c_min).0 >= f2 {
            return c_min;
        }
        // In the exponential band, in y = ln c: g(y) = y − ln c_max + B·clamp(φ(e^y) − f1)
        // increases with y, g(ln c_min) ≤ 0 ≤ g(ln c_max). Newton, kept inside the bracket,
        // from the root for the force carried at c_max (exact when φ does not depend on c).
        let b = (c_max / c_min).ln() / (f2 - f1);
        let ln_max = c_max.ln();
        let g = |y: f64| {
            let c = y.exp();
            let (phi, dphi) = carried(c);
            let over = phi - f1;
            let inside = over > 0.0 && over < f2 - f1;
            let value = y - ln_max + b * over.clamp(0.0, f2 - f1);
            let slope = 1.0 + if inside { b * dphi * c } else { 0.0 };
            (value, slope)
        };
        let (mut lo, mut hi) = (ln_max - b * (f2 - f1), ln_max);
        let mut y = (ln_max - b * (at_max - f1)).clamp(lo, hi);
        for _ in 0..MAX_ITERATIONS {
            let (value, slope) = g(y);
            if value == 0.0 {
                return y.exp();
            }
            if value > 0.0 {
                hi = y;
            } else {
                lo = y;
            }
            let newton = y - value / slope;
            if (newton - y).abs() <= 1e-11 * (1.0 + y.abs()) {
                return newton.exp();
            }
            // Newton strictly inside the bracket, else bisection (no cycling at its ends).
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            y = next;
        }
        y.exp()
    }

    /// Why the parameters are unusable, as (field, message); `None` when valid.
    pub fn problem(&self) -> Option<(&'static str, String)> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        match *self {
            Damper::Linear(c) if !positive(c) => Some((
                "damper",
                format!("Linear coefficient must be a positive number, got {c}"),
            )),
            Damper::Linear(_) => None,
            Damper::ForceDependent {
                c_max,
                c_min,
                f1,
                f2,
            } => {
                if !(positive(c_min) && positive(c_max) && c_min <= c_max) {
                    Some((
                        "damper",
                        format!(
                            "needs 0 < c_min <= c_max (N·s/m), got c_min {c_min}, c_max {c_max}"
                        ),
                    ))
                } else if !(f1.is_finite() && f2.is_finite() && f1 >= 0.0 && f1 < f2) {
                    Some((
                        "damper",
                        format!("needs 0 <= f1 < f2, got f1 {f1}, f2 {f2}"),
                    ))
                } else {
                    None
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FDD: Damper = Damper::ForceDependent {
        c_max: 100.0,
        c_min: 1.0,
        f1: 0.1,
        f2: 0.5,
    };

    #[test]
    fn coefficient_is_continuous_at_both_thresholds() {
        assert_eq!(FDD.coefficient(0.0), 100.0);
        assert!((FDD.coefficient(0.1 + 1e-12) - 100.0).abs() < 1e-6);
        assert!((FDD.coefficient(0.5 - 1e-12) - 1.0).abs() < 1e-6);
        assert_eq!(FDD.coefficient(3.0), 1.0);
        let mid = FDD.coefficient(0.3);
        assert!((mid - 10.0).abs() < 1e-9, "{mid}");
    }

    #[test]
    fn consistent_coefficient_satisfies_its_fixed_point() {
        // A damper carrying c·rate at coefficient c, for rates that land in every band.
        for rate in [1e-4, 1e-3, 5e-3, 0.02, 0.1, 1.0] {
            let c = FDD.consistent_coefficient(|c| (c * rate, rate));
            let back = FDD.coefficient(c * rate);
            assert!(
                (c - back).abs() <= 1e-9 * c,
                "rate {rate}: c {c}, c2(f) {back}"
            );
        }
        assert_eq!(
            Damper::Linear(7.0).consistent_coefficient(|c| (c, 1.0)),
            7.0
        );
    }

    #[test]
    fn bad_parameters_are_named() {
        assert!(Damper::Linear(-1.0).problem().is_some());
        let swapped = Damper::ForceDependent {
            c_max: 1.0,
            c_min: 2.0,
            f1: 0.0,
            f2: 1.0,
        };
        assert!(swapped.problem().unwrap().1.contains("c_min"));
        assert!(FDD.problem().is_none());
    }
}
