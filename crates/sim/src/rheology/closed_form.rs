//! The closed-form creep and recovery of one massless element under a force step
//! (PHYSICS.md §3, "Closed form to test against").

/// Elongation `u(t)` of one element (Voigt k, c1 in series with a linear damper c2, ratio
/// unclamped) under a constant force `force` applied at t = 0 and removed at `release`.
///
/// Loaded: `u = F/k (1 − e^{−kt/c1}) + F t/c2`; after release the Voigt part relaxes as
/// `e^{−k(t − t1)/c1}` and the damper's `F t1/c2` stays. Exact for the element (the two
/// parts' lengths add), small strain or not; it ignores the node's inertia.
// PHYSICS.md §3, closed form.
pub fn creep_recovery(stiffness: f64, c1: f64, c2: f64, force: f64, release: f64, t: f64) -> f64 {
    let voigt = |t: f64| force / stiffness * (1.0 - (-stiffness * t / c1).exp());
    if t <= release {
        voigt(t) + force * t / c2
    } else {
        voigt(release) * (-stiffness * (t - release) / c1).exp() + force * release / c2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuous_at_release_and_tends_to_the_damper_share() {
        let (k, c1, c2, f, t1) = (100.0, 5.0, 50.0, 0.2, 1.0);
        let before = creep_recovery(k, c1, c2, f, t1, t1);
        let after = creep_recovery(k, c1, c2, f, t1, t1 + 1e-12);
        assert!((before - after).abs() < 1e-12);
        let late = creep_recovery(k, c1, c2, f, t1, 100.0);
        assert!((late - f * t1 / c2).abs() < 1e-12);
    }
}
