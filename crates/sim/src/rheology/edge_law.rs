//! The element law of the body's force pass, with the constants of each material folded
//! once: the same equations as [`ElementParams::respond`](super::ElementParams::respond)
//! (PHYSICS.md §3, eqs. (1)–(5) [reconstructed]), written per unit rest length so that an
//! edge needs only its rest length and the material index, and with one reciprocal of the
//! edge length instead of divisions by `(c1 + c2)·L`.

use super::damper::Damper;
use super::material::RheologyMaterial;

/// A material's element law, ready for the force pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum EdgeLaw {
    /// A linear series damper: the common case, evaluated inline.
    Linear {
        /// Voigt spring modulus K, Pa (`k = K·L0`).
        stiffness: f64,
        /// Voigt viscosity η1, Pa·s (`c1 = η1·L0`).
        eta1: f64,
        /// Series viscosity η2, Pa·s (`c2 = η2·L0`).
        eta2: f64,
        /// `1 / (η1 + η2)`, 1/(Pa·s).
        inv_eta_sum: f64,
        /// Voigt ratio at rest r (natural length `r·L0`).
        rest_ratio: f64,
        /// Clamp a_min.
        ratio_min: f64,
        /// Clamp a_max.
        ratio_max: f64,
    },
    /// A force-dependent damper: the general element (its c2 is solved per edge).
    General(RheologyMaterial),
}

impl EdgeLaw {
    /// The law of `m`.
    pub(crate) fn of(m: &RheologyMaterial) -> Self {
        match m.damper {
            Damper::Linear(eta2) if m.voigt_viscosity + eta2 > 0.0 => EdgeLaw::Linear {
                stiffness: m.stiffness,
                eta1: m.voigt_viscosity,
                eta2,
                inv_eta_sum: 1.0 / (m.voigt_viscosity + eta2),
                rest_ratio: m.rest_ratio,
                ratio_min: m.ratio_min,
                ratio_max: m.ratio_max,
            },
            _ => EdgeLaw::General(*m),
        }
    }

    /// Tension (N, positive pulls the nodes together) and ratio rate ȧ (1/s) of an edge
    /// of rest length `l0`, length `len` (`inv_len = 1/len`), length rate `len_rate` and
    /// Voigt ratio `ratio`.
    ///
    /// With `c1 = η1·L0`, `c2 = η2·L0`, `k = K·L0`, `l = r·L0` every term of eq. (3) has
    /// the factor L0, which cancels:
    /// `ȧ = ((η2(1 − a) − η1·a)·L̇ − K(aL − rL0)) / ((η1 + η2)·L)`, and the tension is
    /// `L0·(K(aL − rL0) + η1(ȧL + aL̇))` (eq. (1)) or, with `a` held at a clamp bound,
    /// `L0·(a(K(aL − rL0) + η1·a·L̇) + (1 − a)²·η2·L̇)` (eqs. (4), (5)).
    #[inline(always)]
    pub(crate) fn respond(
        &self,
        l0: f64,
        len: f64,
        inv_len: f64,
        len_rate: f64,
        ratio: f64,
    ) -> (f64, f64) {
        match *self {
            EdgeLaw::Linear {
                stiffness,
                eta1,
                eta2,
                inv_eta_sum,
                rest_ratio,
                ratio_min,
                ratio_max,
            } => {
                let a = ratio.clamp(ratio_min, ratio_max);
                // PHYSICS.md §3, eq. (3) [reconstructed], per unit rest length.
                let spring = stiffness * (a * len - rest_ratio * l0);
                let rate =
                    ((eta2 * (1.0 - a) - eta1 * a) * len_rate - spring) * inv_eta_sum * inv_len;
                let held = (a >= ratio_max && rate > 0.0) || (a <= ratio_min && rate < 0.0);
                if held {
                    // PHYSICS.md §3, eqs. (4), (5): a held; eqs. (1), (2) with ȧ = 0.
                    let b = 1.0 - a;
                    let tension =
                        l0 * (a * (spring + eta1 * a * len_rate) + b * b * eta2 * len_rate);
                    (tension, 0.0)
                } else {
                    // PHYSICS.md §3, eq. (1): f = k(aL − l) + c1(ȧL + aL̇).
                    let tension = l0 * (spring + eta1 * (rate * len + a * len_rate));
                    (tension, rate)
                }
            }
            EdgeLaw::General(m) => {
                let r = m
                    .element(l0)
                    .respond(m.rest_ratio * l0, len, len_rate, ratio);
                (r.tension, r.ratio_rate)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(damper: Damper, lo: f64, rest: f64, hi: f64) -> RheologyMaterial {
        RheologyMaterial {
            stiffness: 1.0e4,
            voigt_viscosity: 1.0e3,
            damper,
            rest_ratio: rest,
            ratio_min: lo,
            ratio_max: hi,
            density: 1000.0,
        }
    }

    #[test]
    fn folded_law_matches_the_element_free_and_clamped() {
        let materials = [
            material(Damper::Linear(5.0e3), 0.8, 0.9, 1.0),
            material(Damper::Linear(1.0e9), 1.0, 1.0, 1.0),
            material(Damper::Linear(2.0e3), 0.0, 0.5, 1.0),
        ];
        let mut checked = [0usize; 2];
        for m in &materials {
            let law = EdgeLaw::of(m);
            assert!(matches!(law, EdgeLaw::Linear { .. }));
            for (l0, stretch, len_rate, ratio) in [
                (0.05, 1.02, 0.3, 0.9),
                (0.05, 0.97, -0.4, 0.85),
                (0.01, 1.1, 0.01, 1.0),
                (0.02, 0.9, -0.2, 0.8),
                (0.03, 1.0, 0.0, 0.95),
                (0.05, 0.95, 0.5, 0.8),
                (0.04, 1.05, -0.5, 1.0),
            ] {
                let len = l0 * stretch;
                let (tension, rate) = law.respond(l0, len, 1.0 / len, len_rate, ratio);
                let want = m
                    .element(l0)
                    .respond(m.rest_ratio * l0, len, len_rate, ratio);
                let scale = want.tension.abs().max(1e-9);
                assert!(
                    (tension - want.tension).abs() <= 1e-9 * scale,
                    "{m:?} {tension} vs {}",
                    want.tension
                );
                assert!(
                    (rate - want.ratio_rate).abs() <= 1e-9 * want.ratio_rate.abs().max(1e-12),
                    "{rate} vs {}",
                    want.ratio_rate
                );
                checked[want.clamped as usize] += 1;
            }
        }
        assert!(checked[0] > 0 && checked[1] > 0, "{checked:?}");
    }

    #[test]
    fn force_dependent_damper_takes_the_general_element() {
        let m = material(
            Damper::ForceDependent {
                c_max: 1e6,
                c_min: 1e4,
                f1: 100.0,
                f2: 400.0,
            },
            0.8,
            0.9,
            1.0,
        );
        let law = EdgeLaw::of(&m);
        assert!(matches!(law, EdgeLaw::General(_)));
        let (t, r) = law.respond(0.05, 0.051, 1.0 / 0.051, 0.2, 0.9);
        let want = m
            .element(0.05)
            .respond(m.rest_ratio * 0.05, 0.051, 0.2, 0.9);
        assert_eq!((t, r), (want.tension, want.ratio_rate));
    }
}
