//! Issue 9, test 3: the force-dependent damper keeps a block's shape under its own weight
//! (seed §6) yet lets a press deform it permanently.

mod rheology_support;

use incise_sim::rheology::{Damper, PressProtocol, Specimen, press_and_release, sag_under_gravity};
use rheology_support::preset;

#[test]
fn force_dependent_damper_holds_the_weight_but_yields_to_a_press() {
    let fdd = preset("rheological_fdd");
    let Damper::ForceDependent { c_min, .. } = fdd.damper else {
        panic!("rheological_fdd must have a force-dependent damper");
    };
    // Without it: the same material with the damper fixed at the value it takes under a
    // press, c_min.
    let linear = fdd.with_damper(Damper::Linear(c_min));
    let block = Specimen::coarse();
    let sag = |m| {
        let curve = sag_under_gravity(&m, &block, 9.81, 0.5, 5.0, 10).expect("gravity run");
        curve.last().unwrap().1
    };
    let (with, without) = (sag(fdd), sag(linear));
    eprintln!(
        "sag over 5 s: {:.3} mm with the force-dependent damper, {:.3} mm without ({:.1} %)",
        with * 1e3,
        without * 1e3,
        100.0 * with / without
    );
    assert!(without > 0.0 && with < 0.1 * without);

    let press = press_and_release(&fdd, &PressProtocol::standard(block, 0.5)).expect("press");
    eprintln!(
        "press: max {:.2} mm, residual {:.2} mm ({:.1} %)",
        press.max_depth() * 1e3,
        press.residual_depth() * 1e3,
        100.0 * press.residual_fraction()
    );
    assert!(press.residual_fraction() > 0.1, "no permanent dent");
}
