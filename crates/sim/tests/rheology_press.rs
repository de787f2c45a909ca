//! Issue 9, test 2: the seed's press-and-release (Figs. 3–6) with the shipped presets —
//! viscoelastic returns, plastic keeps the dent, rheological keeps part of it, more the
//! longer it is held.

mod rheology_support;

use incise_sim::rheology::{PressProtocol, Specimen, press_and_release};
use rheology_support::preset;

fn residual(name: &str, hold: f64) -> f64 {
    let out = press_and_release(
        &preset(name),
        &PressProtocol::standard(Specimen::standard(), hold),
    )
    .expect("press run");
    eprintln!(
        "{name}, hold {hold} s: max {:.3} mm, residual {:.3} mm ({:.2} %), {} RK4 steps of {:.2e} s",
        out.max_depth() * 1e3,
        out.residual_depth() * 1e3,
        100.0 * out.residual_fraction(),
        out.steps,
        out.substep
    );
    assert!(out.max_depth() > 0.029, "the indenter pressed 30 mm");
    out.residual_fraction()
}

#[test]
fn viscoelastic_returns_to_its_shape() {
    let r = residual("viscoelastic", 0.5);
    assert!(r.abs() < 0.01, "residual {r}");
}

#[test]
fn plastic_keeps_the_dent() {
    let r = residual("plastic", 0.5);
    assert!(r > 0.95, "residual {r}");
}

#[test]
fn rheological_keeps_part_of_the_dent_and_more_when_held_longer() {
    let holds = [0.1, 0.5, 1.0];
    let r: Vec<f64> = holds.iter().map(|&h| residual("rheological", h)).collect();
    assert!(r.iter().all(|&x| x > 0.01 && x < 0.95), "residuals {r:?}");
    assert!(
        r[0] < r[1] && r[1] < r[2],
        "residual must grow with hold time: {r:?}"
    );
}
