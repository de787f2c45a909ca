//! The three-element element of one edge: a Voigt unit (spring k, damper c1, natural
//! length l) holding the fraction `a` of the edge length L, in series with a damper c2
//! holding the rest (PHYSICS.md §3, eqs. (1)–(5) [reconstructed]).
//!
//! Clamping (eqs. (4), (5)): while `a` sits at a bound and eq. (3) would push it out, the
//! ratio is held (`ȧ = 0`). The two parts then no longer carry the same force, and the
//! edge tension is the one that follows from the element's energy `½k(aL − l)²` and its
//! dissipation `½c1(d(aL)/dt)² + ½c2(d((1−a)L)/dt)²` with `a` fixed:
//! `T = a·f_Voigt + (1 − a)·f_damper`. Its power `T·L̇` is the spring's energy rate plus
//! `(a²c1 + (1−a)²c2)·L̇² ≥ 0`, so a clamped element never creates energy; with
//! `a_min = a_max = 1` it is exactly the Voigt model `k(L − l) + c1·L̇` (the viscoelastic
//! preset). This reading of "clamp a after each step" is ours; the seed only says that the
//! value is reset to the bound.

use super::damper::Damper;

/// Constants of one three-element element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementParams {
    /// Voigt spring stiffness k, N/m.
    pub stiffness: f64,
    /// Voigt damper c1, N·s/m.
    pub voigt_damping: f64,
    /// Series damper c2.
    pub damper: Damper,
    /// Lower clamp a_min of the Voigt ratio.
    pub ratio_min: f64,
    /// Upper clamp a_max of the Voigt ratio.
    pub ratio_max: f64,
}

/// What an element does at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementResponse {
    /// Tension along the edge, N (positive pulls the two nodes together).
    pub tension: f64,
    /// Rate of the Voigt ratio ȧ, 1/s (0 while the ratio is clamped).
    pub ratio_rate: f64,
    /// Whether the ratio is held at a clamp bound.
    pub clamped: bool,
}

impl ElementParams {
    /// Tension and ratio rate at edge length `length` (m, > 0), its rate `length_rate`
    /// (m/s) and Voigt ratio `ratio`, for Voigt natural length `natural_length` (m).
    ///
    /// `ratio` is clamped to `[a_min, a_max]` first (RK4 stages may overshoot a bound).
    #[inline]
    pub fn respond(
        &self,
        natural_length: f64,
        length: f64,
        length_rate: f64,
        ratio: f64,
    ) -> ElementResponse {
        let (k, c1) = (self.stiffness, self.voigt_damping);
        let a = ratio.clamp(self.ratio_min, self.ratio_max);
        let spring = k * (a * length - natural_length);
        // (1) = (2) ⇒ the common force is f = c2·(c1·L̇ + k(aL − l))/(c1 + c2); the damper's
        // coefficient must agree with it (force-dependent damper).
        let drive = c1 * length_rate + spring;
        let c2 = match self.damper {
            Damper::Linear(c) => c,
            fdd => fdd.consistent_coefficient(|c| {
                let s = c1 + c;
                (c * drive.abs() / s, c1 * drive.abs() / (s * s))
            }),
        };
        // PHYSICS.md §3, eq. (3) [reconstructed].
        let rate =
            (c2 * (1.0 - a) * length_rate - c1 * a * length_rate - spring) / ((c1 + c2) * length);
        let held = (a >= self.ratio_max && rate > 0.0) || (a <= self.ratio_min && rate < 0.0);
        if !held {
            // PHYSICS.md §3, eq. (1): f = k(aL − l) + c1(ȧL + aL̇).
            return ElementResponse {
                tension: spring + c1 * (rate * length + a * length_rate),
                ratio_rate: rate,
                clamped: false,
            };
        }
        // PHYSICS.md §3, eqs. (4), (5): a held at its bound; eqs. (1), (2) with ȧ = 0.
        let damper_rate = (1.0 - a) * length_rate;
        let c2 = match self.damper {
            Damper::Linear(c) => c,
            fdd => fdd.consistent_coefficient(|c| (c * damper_rate.abs(), damper_rate.abs())),
        };
        let voigt_force = spring + c1 * a * length_rate;
        let damper_force = c2 * damper_rate;
        ElementResponse {
            tension: a * voigt_force + (1.0 - a) * damper_force,
            ratio_rate: 0.0,
            clamped: true,
        }
    }

    /// Elastic energy of the Voigt spring, `½k(aL − l)²`, J.
    pub fn stored_energy(&self, natural_length: f64, length: f64, ratio: f64) -> f64 {
        let stretch = ratio * length - natural_length;
        0.5 * self.stiffness * stretch * stretch
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rheo() -> ElementParams {
        ElementParams {
            stiffness: 100.0,
            voigt_damping: 2.0,
            damper: Damper::Linear(30.0),
            ratio_min: 0.2,
            ratio_max: 0.9,
        }
    }

    #[test]
    fn free_element_carries_the_same_force_in_both_parts() {
        let p = rheo();
        let (l, len, rate, a) = (0.004, 0.0105, -0.03, 0.41);
        let r = p.respond(l, len, rate, a);
        assert!(!r.clamped);
        // eq. (2): the damper's force equals the Voigt unit's.
        let damper = 30.0 * (-r.ratio_rate * len + (1.0 - a) * rate);
        assert!(
            (damper - r.tension).abs() < 1e-12,
            "{damper} vs {}",
            r.tension
        );
    }

    #[test]
    fn clamp_holds_the_ratio_only_when_pushed_outward() {
        let p = rheo();
        // Compressed fast at a = a_min: the Voigt part takes c2/(c1 + c2) of L̇ > a·L̇, so
        // eq. (3) gives ȧ < 0 and the ratio is held.
        let held = p.respond(0.002, 0.01, -0.5, 0.2);
        assert!(held.clamped && held.ratio_rate == 0.0);
        // Stretched at a = a_min: ȧ > 0 moves it back inside, so it is free.
        let free = p.respond(0.002, 0.01, 0.5, 0.2);
        assert!(!free.clamped && free.ratio_rate > 0.0);
    }

    #[test]
    fn pinned_ratio_of_one_is_the_voigt_model() {
        let p = ElementParams {
            ratio_min: 1.0,
            ratio_max: 1.0,
            damper: Damper::Linear(1e9),
            ..rheo()
        };
        for (len, rate) in [(0.011, 0.2), (0.009, -0.3), (0.0105, -0.01)] {
            let r = p.respond(0.01, len, rate, 1.0);
            let voigt = 100.0 * (len - 0.01) + 2.0 * rate;
            assert!(
                (r.tension - voigt).abs() < 1e-12,
                "{} vs {voigt}",
                r.tension
            );
        }
    }

    #[test]
    fn clamped_element_dissipates() {
        // T·L̇ − d/dt(½k(aL − l)²) = (a²c1 + (1−a)²c2)·L̇² at fixed a.
        let p = rheo();
        let (l, len, rate, a) = (0.0015, 0.01, -0.4, 0.2);
        let r = p.respond(l, len, rate, a);
        assert!(r.clamped);
        let spring_power = 100.0 * (a * len - l) * a * rate;
        let dissipation = r.tension * rate - spring_power;
        let expected = (a * a * 2.0 + (1.0 - a) * (1.0 - a) * 30.0) * rate * rate;
        assert!((dissipation - expected).abs() < 1e-12 && dissipation > 0.0);
    }
}
