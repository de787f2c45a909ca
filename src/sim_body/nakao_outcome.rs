//! A Nakao body's result for a replay or rollback check: its counts after cutting and a
//! hash of the whole model (dynamic state, nodes, tets, springs, masses, cut faces).

use incise_sim::mass_spring::MassSpringModel;

use super::outcome::{Outcome, StateHash};

/// The outcome of `m`: "N nodes, T tets" and a hash of every bit of its state.
pub fn model_outcome(m: &MassSpringModel) -> Outcome {
    let mut h = StateHash::new();
    h.reals([m.time(), m.stable_dt()])
        .vectors(m.positions())
        .vectors(m.velocities())
        .vectors(m.reference_positions())
        .reals(m.masses().iter().copied())
        .reals(m.tet_masses().iter().copied())
        .ints(m.tets().iter().flatten().map(|&n| u64::from(n)))
        .ints(m.tet_cut_faces().iter().map(|&f| u64::from(f)))
        .ints(m.twins().iter().flatten().map(|&n| u64::from(n)));
    for i in 0..m.node_count() {
        h.ints([u64::from(m.fixed_axes(i).0)]);
        for s in m.springs_of(i) {
            h.ints([u64::from(s.node), s.rest.to_bits(), s.stiffness.to_bits()]);
        }
    }
    Outcome {
        summary: format!("{} nodes, {} tets", m.node_count(), m.tet_count()),
        hash: h.finish(),
        released: None,
    }
}
