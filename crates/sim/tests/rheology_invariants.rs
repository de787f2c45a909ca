//! Issue 9, test 4: the Voigt ratio never leaves [a_min, a_max], and a body's energy never
//! grows without external work — free, under gravity, and with clamped elements.

mod rheology_support;

use glam::DVec3;
use incise_sim::rheology::{FlatIndenter, PressProtocol, RheologyBody, Specimen, SpecimenMesh};
use rheology_support::preset;

/// A body of `name` on the table, pressed by the standard indenter (hold 0.5 s).
fn pressed(name: &str) -> (SpecimenMesh, RheologyBody, PressProtocol) {
    let protocol = PressProtocol::standard(Specimen::standard(), 0.5);
    let specimen = protocol.specimen.mesh().unwrap();
    let mut body = specimen.body(preset(name), 0.0).unwrap();
    body.set_indenter(Some(FlatIndenter {
        centre: [0.0, 0.0],
        half_size: protocol.indenter_half_size,
        rest_top: protocol.specimen.size.z,
        schedule: protocol.schedule,
        candidates: specimen.top.clone(),
    }));
    (specimen, body, protocol)
}

#[test]
fn ratios_stay_within_their_clamps_and_reach_them() {
    let (_, mut body, protocol) = pressed("rheological");
    let h = body.stability().safe_step();
    let steps = (protocol.duration() / h) as usize;
    let mut at_bound = vec![false; body.edges().len()];
    for _ in 0..steps {
        body.step(h).unwrap();
        for (e, &a) in body.ratios().iter().enumerate() {
            let (lo, hi) = body.ratio_bounds(e);
            assert!(a >= lo && a <= hi, "edge {e}: a = {a} left [{lo}, {hi}]");
            at_bound[e] |= a == lo || a == hi;
        }
    }
    let clamped = at_bound.iter().filter(|&&b| b).count();
    eprintln!(
        "{clamped} of {} edges reached a clamp bound",
        at_bound.len()
    );
    assert!(clamped > 0, "the press must drive some edges to a bound");
}

/// Total energy (kinetic + Voigt springs + gravity) after every step must not rise.
fn assert_energy_never_grows(body: &mut RheologyBody, steps: usize, what: &str) {
    let energy = |b: &RheologyBody| b.kinetic_energy() + b.stored_energy() + b.gravity_energy();
    let h = body.stability().safe_step();
    let start = energy(body);
    let mut last = start;
    let mut scale = body.kinetic_energy() + body.stored_energy();
    for n in 0..steps {
        body.step(h).unwrap();
        let e = energy(body);
        scale = scale.max(body.kinetic_energy() + body.stored_energy());
        assert!(
            e <= last + 1e-9 * scale,
            "{what}: energy rose from {last:e} to {e:e} J at step {n}"
        );
        last = e;
    }
    eprintln!("{what}: energy {start:.4e} -> {last:.4e} J over {steps} steps");
    assert!(last < start, "{what}: nothing was dissipated");
}

#[test]
fn energy_never_grows_without_external_work() {
    for name in [
        "elastic",
        "viscoelastic",
        "plastic",
        "rheological",
        "rheological_fdd",
    ] {
        // Free: the block on the table shaken by an initial velocity field.
        let specimen = Specimen::standard().mesh().unwrap();
        let mut body = specimen.body(preset(name), 0.0).unwrap();
        for i in 0..body.node_count() {
            let p = body.position(i);
            let v = DVec3::new((7.0 * p.y).sin(), (5.0 * p.z).cos(), (3.0 * p.x).sin()) * 0.2;
            body.set_velocity(i, v);
        }
        assert_energy_never_grows(&mut body, 400, &format!("{name}, shaken"));
        // Under gravity (its potential counted).
        let mut body = specimen.body(preset(name), 9.81).unwrap();
        assert_energy_never_grows(&mut body, 400, &format!("{name}, gravity"));
    }
    // After a press, with many elements held at a clamp: lift the indenter off and let go.
    let (_, mut body, protocol) = pressed("rheological");
    body.advance(protocol.schedule.press + protocol.schedule.hold)
        .unwrap();
    body.set_indenter(None);
    assert_energy_never_grows(&mut body, 2000, "rheological, released after a press");
}
