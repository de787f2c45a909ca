//! Issue 9, tests 1 and 5: one three-element element against the closed-form creep and
//! recovery (PHYSICS.md §3), and the fourth-order convergence of its RK4 integration.

use incise_sim::rheology::{CreepTest, Damper, ElementParams, creep_recovery};

/// k = 100 N/m, c1 = 5 N·s/m, c2 = 50 N·s/m, ratio bounds [0, 1] (never reached here).
fn element() -> ElementParams {
    ElementParams {
        stiffness: 100.0,
        voigt_damping: 5.0,
        damper: Damper::Linear(50.0),
        ratio_min: 0.0,
        ratio_max: 1.0,
    }
}

#[test]
fn creep_and_recovery_match_the_closed_form_within_one_percent() {
    // 0.5 N for 1 s on a 10 cm edge (a0 = 0.5): 5 mm of Voigt creep, 10 mm of flow. The
    // loaded node weighs 0.1 g, so its inertia (time m/c ≈ 2e-5 s) is negligible.
    let test = CreepTest {
        element: element(),
        rest_length: 0.1,
        rest_ratio: 0.5,
        node_mass: 1e-4,
        force: 0.5,
        release: 1.0,
    };
    let h = 0.5 * test.max_step();
    let samples = test.run(h, 3.0, 200).unwrap();
    let exact = |t: f64| creep_recovery(100.0, 5.0, 50.0, 0.5, 1.0, t);
    let peak = exact(1.0);
    let (mut worst, mut at) = (0.0f64, 0.0);
    for s in &samples {
        let err = (s.elongation - exact(s.time)).abs();
        if err > worst {
            (worst, at) = (err, s.time);
        }
        assert!(
            s.ratio > 0.0 && s.ratio < 1.0,
            "ratio {} hit a clamp",
            s.ratio
        );
    }
    let last = samples.last().unwrap();
    eprintln!(
        "closed form: worst error {:.3e} m at t = {at:.3} s ({:.4} % of the peak {peak:.5} m); \
         residual {:.6} m vs F t1/c2 = {:.6} m",
        worst,
        100.0 * worst / peak,
        last.elongation,
        0.5 / 50.0
    );
    assert!(worst < 0.01 * peak, "error {worst} above 1 % of {peak}");
    // After 2 s of recovery (40 Voigt time constants) only the damper's share is left.
    assert!((last.elongation - 0.01).abs() < 0.01 * 0.01);
}

#[test]
fn rk4_error_falls_sixteenfold_when_the_step_halves() {
    // A heavier node (10 g) so that the element rings (ω = 100 rad/s, ζ ≈ 0.2): a smooth,
    // non-trivial trajectory of position, velocity and ratio.
    let test = CreepTest {
        element: ElementParams {
            voigt_damping: 0.5,
            damper: Damper::Linear(5.0),
            ..element()
        },
        rest_length: 0.1,
        rest_ratio: 0.5,
        node_mass: 0.01,
        force: 0.5,
        release: 1.0,
    };
    let end = 0.2;
    let final_state = |n: usize| {
        let s = test.run(end / n as f64, end, n).unwrap();
        let last = *s.last().unwrap();
        (last.elongation, last.ratio)
    };
    let reference = final_state(25_600);
    let error = |n: usize| {
        let (u, a) = final_state(n);
        // Elongation (m) and ratio errors, each relative to its own scale.
        ((u - reference.0) / 0.005).abs() + (a - reference.1).abs()
    };
    let steps = [100, 200, 400, 800];
    let errors: Vec<f64> = steps.iter().map(|&n| error(n)).collect();
    let ratios: Vec<f64> = errors.windows(2).map(|w| w[0] / w[1]).collect();
    let shown: Vec<String> = errors.iter().map(|e| format!("{e:.3e}")).collect();
    eprintln!("RK4 errors {shown:?} for {steps:?} steps; ratios {ratios:.2?}");
    assert!(end / 100.0 < test.max_step());
    for r in &ratios[1..] {
        assert!((14.0..18.5).contains(r), "error ratio {r} is not ≈ 16");
    }
}

#[test]
fn a_step_above_the_stability_limit_is_refused_with_the_limit() {
    let test = CreepTest {
        element: element(),
        rest_length: 0.1,
        rest_ratio: 0.5,
        node_mass: 1e-4,
        force: 0.5,
        release: 1.0,
    };
    let limit = test.max_step();
    let e = test.run(2.0 * limit, 1.0, 1).unwrap_err().to_string();
    assert!(e.contains("stability limit"), "{e}");
    assert!(e.contains(&format!("{limit:e}")), "{e}");
}
