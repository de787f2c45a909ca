//! Localisation (PHYSICS.md §2.5): nodes deeper than level d do not move; the free set
//! follows the tool; the refresh-rate manager bounds the free set.

use glam::DVec3;
use incise_sim::mass_spring::{Clock, LocalLoop, LocalLoopParams};
use incise_sim::nakao_cut::{BladePose, CutParams, Cutter, plate_model};

/// A scripted clock: every reading is 0.1 ms after the previous one.
struct StepClock(std::cell::Cell<f64>);

impl Clock for StepClock {
    fn now(&self) -> f64 {
        let t = self.0.get() + 1e-4;
        self.0.set(t);
        t
    }
}

fn cut_plate() -> incise_sim::mass_spring::MassSpringModel {
    let mut m = plate_model(0.04).unwrap();
    let mut cutter = Cutter::new(CutParams::default());
    let blade = |x: f64| BladePose {
        heel: DVec3::new(x, 0.0011, -0.002),
        tip: DVec3::new(x, 0.0011, 0.006),
    };
    cutter.begin(&m, blade(-0.02));
    cutter.advance(&mut m, blade(0.02));
    m
}

#[test]
fn nodes_beyond_level_d_do_not_move() {
    let mut m = cut_plate();
    let before = m.positions().to_vec();
    let params = LocalLoopParams {
        max_level: 4,
        ..LocalLoopParams::default()
    };
    let mut local = LocalLoop::new(params, StepClock(Default::default()));
    let tip = DVec3::new(0.0, 0.0011, 0.004);
    let dt = m.stable_dt();
    let mut stats = None;
    // The wound opens under the tool, so the nearest node (the root) may change: a node is
    // frozen when no loop freed it.
    let mut ever_free = vec![false; m.node_count()];
    for _ in 0..400 {
        stats = Some(local.step(&mut m, tip, dt));
        for &v in local.hierarchy().free_nodes() {
            ever_free[v as usize] = true;
        }
    }
    let stats = stats.unwrap();
    assert_eq!(stats.levels, 5, "levels 0..=4");
    let (mut moved_free, mut frozen) = (0, 0);
    for (i, (a, b)) in before.iter().zip(m.positions()).enumerate() {
        if ever_free[i] {
            moved_free += usize::from((*a - *b).length() > 1e-6);
        } else {
            frozen += 1;
            assert_eq!(a, b, "frozen node {i} moved");
        }
    }
    assert!(
        moved_free > 10,
        "the wound opens near the tool ({moved_free} nodes moved)"
    );
    assert!(frozen > m.node_count() / 2);
    // The scripted clock advances 0.1 ms per reading; a one-step loop reads it six
    // times (start, after localising, around the force and integration phases, end).
    assert!((stats.ms - 0.5).abs() < 1e-9, "{}", stats.ms);
    for (phase, ms) in [
        ("localise", stats.localise_ms),
        ("force", stats.force_ms),
        ("integrate", stats.integrate_ms),
    ] {
        assert!((ms - 0.1).abs() < 1e-9, "{phase}: {ms}");
    }
    assert_eq!(stats.level(), 4);
    assert_eq!(
        stats.free_nodes,
        local.hierarchy().free_nodes().len(),
        "stats count the last loop's free set"
    );
    // The free set is the level-d neighbourhood of the tool: a shallower level frees a
    // strict subset of a deeper one around the same root.
    let free_at = |max_level| {
        let mut m = cut_plate();
        let params = LocalLoopParams {
            max_level,
            ..LocalLoopParams::default()
        };
        let mut l = LocalLoop::new(params, StepClock(Default::default()));
        l.step(&mut m, tip, dt);
        (0..m.node_count() as u32)
            .filter(|&i| l.hierarchy().is_free(i))
            .collect::<std::collections::BTreeSet<_>>()
    };
    let (two, four) = (free_at(2), free_at(4));
    assert!(
        !two.is_empty() && two.len() < four.len() && two.is_subset(&four),
        "level 2 frees {} nodes, level 4 {}",
        two.len(),
        four.len()
    );
}

#[test]
fn free_set_follows_the_tool_and_the_manager_caps_it() {
    let mut m = cut_plate();
    let params = LocalLoopParams {
        budget_ms: Some(0.05),
        min_nodes: 20,
        max_nodes: 300,
        ..LocalLoopParams::default()
    };
    // 0.2 ms of force + integration per loop against a 0.05 ms budget: the manager shrinks
    // the set to its minimum.
    let mut local = LocalLoop::new(params, StepClock(Default::default()));
    let dt = m.stable_dt();
    let a = local.step(&mut m, DVec3::new(-0.05, 0.03, 0.0), dt);
    for _ in 0..30 {
        local.step(&mut m, DVec3::new(0.05, -0.03, 0.0), dt);
    }
    let b = local.step(&mut m, DVec3::new(0.05, -0.03, 0.0), dt);
    assert_ne!(a.root, b.root);
    let p = m.positions()[b.root as usize];
    assert!((p - DVec3::new(0.05, -0.03, 0.0)).length() < 0.006);
    assert_eq!(b.free_nodes, 20);
    assert_eq!(local.manager().unwrap().free_nodes(), 20);
}

/// A scripted clock whose readings are `.1` s apart: a machine of another speed.
struct PaceClock(std::cell::Cell<f64>, f64);

impl Clock for PaceClock {
    fn now(&self) -> f64 {
        let t = self.0.get() + self.1;
        self.0.set(t);
        t
    }
}

/// 40 budgeted loops of the tool crossing the cut plate, timed by a clock of `pace` s per
/// reading, replaying `replay` when given: each loop's free nodes and the positions after.
fn budgeted_run(pace: f64, replay: Option<&[usize]>) -> (Vec<usize>, Vec<DVec3>) {
    let mut m = cut_plate();
    let params = LocalLoopParams {
        budget_ms: Some(0.3),
        max_level: u32::MAX,
        ..LocalLoopParams::default()
    };
    let mut local = LocalLoop::new(params, PaceClock(Default::default(), pace));
    if let Some(counts) = replay {
        local.replay(counts.iter().copied());
    }
    let dt = m.stable_dt();
    let counts = (0..40)
        .map(|k| {
            let tip = DVec3::new(-0.04 + 0.002 * k as f64, 0.0011, 0.004);
            local.frame(&mut m, tip, dt, 3).free_nodes
        })
        .collect();
    (counts, m.positions().to_vec())
}

/// The manager picks the free set from the measured time, so two machines (clocks of
/// another pace) end elsewhere; replaying the first run's free-node counts, the second
/// reproduces it bit for bit (PHYSICS.md §2.5; docs/reliability.md, Soak).
#[test]
fn a_budgeted_loop_replaying_the_free_node_counts_reproduces_the_run() {
    let (counts, fast) = budgeted_run(1e-5, None);
    let (slow_counts, slow) = budgeted_run(4e-5, None);
    assert_ne!(
        counts, slow_counts,
        "the clocks must make the manager choose otherwise"
    );
    assert_ne!(fast, slow);
    let (replayed_counts, replayed) = budgeted_run(4e-5, Some(&counts));
    assert_eq!(replayed_counts, counts);
    let bits = |x: &[DVec3]| -> Vec<[u64; 3]> {
        x.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
    };
    assert_eq!(bits(&replayed), bits(&fast));
}
