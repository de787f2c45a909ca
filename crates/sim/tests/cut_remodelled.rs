//! `CutReport::remodelled` (what a rollback copy relies on): a blade advance that says it
//! did not remodel left everything but positions, velocities and time bit for bit as it
//! was; along a slow cut of the tensioned plate some advances remodel and some do not.

use glam::DVec3;
use incise_sim::mass_spring::MassSpringModel;
use incise_sim::nakao_cut::{BladePose, CutParams, Cutter, Subdivision, plate_model};

/// Everything of `m` a cut may change, as bits.
fn topology(m: &MassSpringModel) -> Vec<u64> {
    let mut out = vec![m.node_count() as u64, m.stable_dt().to_bits()];
    let v3 = |out: &mut Vec<u64>, p: &DVec3| out.extend(p.to_array().map(f64::to_bits));
    for i in 0..m.node_count() {
        v3(&mut out, &m.reference_positions()[i]);
        out.push(m.masses()[i].to_bits());
        out.push(u64::from(m.fixed_axes(i).0));
        out.extend(m.tets_of(i).iter().map(|&t| u64::from(t)));
        for s in m.springs_of(i) {
            out.extend([u64::from(s.node), s.rest.to_bits(), s.stiffness.to_bits()]);
        }
    }
    for (t, tet) in m.tets().iter().enumerate() {
        out.extend(tet.map(u64::from));
        out.push(m.tet_masses()[t].to_bits());
        out.push(u64::from(m.tet_cut_faces()[t]));
    }
    out.extend(m.twins().iter().flatten().map(|&n| u64::from(n)));
    out
}

#[test]
fn an_advance_that_did_not_remodel_left_the_topology_as_it_was() {
    let mut model = plate_model(0.04).unwrap();
    model.advance(0.05);
    let mut cutter = Cutter::new(CutParams {
        subdivision: Subdivision::Adaptive,
        ..CutParams::default()
    });
    let blade = |x: f64| BladePose {
        heel: DVec3::new(x, -0.0048, -0.002),
        tip: DVec3::new(x, -0.0048, 0.006),
    };
    cutter.begin(&model, blade(-0.07));
    let (mut kept, mut remodelled) = (0, 0);
    // 0.5 mm a frame (the chest scene's 5 cm/s at 100 Hz) over 4 cm.
    for k in 1..=80 {
        let before = topology(&model);
        let r = cutter.advance(&mut model, blade(-0.07 + k as f64 * 0.0005));
        if r.remodelled {
            remodelled += 1;
        } else {
            kept += 1;
            assert!(topology(&model) == before, "advance {k}: {r:?}");
        }
        model.advance(0.01);
    }
    eprintln!("{remodelled} advances remodelled, {kept} did not");
    assert!(remodelled > 0 && kept > 0, "{remodelled} / {kept}");
}
