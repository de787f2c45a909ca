//! The Nakao 2003 chest experiment (PHYSICS.md §2.6, Figs. 15–16) on the procedural chest:
//! its counts against the paper's MRI chest, and the free nodes a fixed level gives along
//! the sternum incision against the paper's. Times depend on the machine and are not
//! pinned here (`incise experiment nakao-chest` prints them beside the paper's).

use std::cell::Cell;

use incise_sim::mass_spring::{Clock, LocalLoopParams};
use incise_sim::nakao_cut::measure::counts;
use incise_sim::nakao_cut::{chest_model, run_chest_cut};

/// A scripted clock (the counts must not depend on timing).
struct StepClock(Cell<f64>);

impl Clock for StepClock {
    fn now(&self) -> f64 {
        let t = self.0.get() + 1e-6;
        self.0.set(t);
        t
    }
}

/// Relative distance of `x` from the range `[lo, hi]` (0 inside).
fn outside(x: f64, lo: f64, hi: f64) -> f64 {
    if x < lo {
        (lo - x) / lo
    } else if x > hi {
        (x - hi) / hi
    } else {
        0.0
    }
}

/// Paper: 17,582 nodes, 100,807 edges, 19,964 triangles, 73,279 tets. Ours: the same
/// nodes; edges within 1 %, surface triangles within 5 %, tets within 0.5 %.
#[test]
fn chest_counts_match_the_paper() {
    let c = counts(&chest_model().unwrap());
    eprintln!("{c:?}");
    assert_eq!(c.nodes, 17_582);
    for (name, got, paper, tol) in [
        ("edges", c.edges, 100_807.0, 0.01),
        ("triangles", c.triangles, 19_964.0, 0.05),
        ("tets", c.tets, 73_279.0, 0.005),
    ] {
        let rel = (got as f64 - paper) / paper;
        assert!(
            rel.abs() <= tol,
            "{name}: {got} vs {paper} ({:+.2} %)",
            rel * 100.0
        );
    }
}

/// Paper: level 4 frees 219–232 nodes, level 6 346–480. Ours (a wall three nodes thick):
/// the median over 60 loops of the incision within 30 % of the paper's range (level 4:
/// 157, −28 %; level 6: 333, inside).
#[test]
fn fixed_levels_free_about_the_papers_node_counts() {
    let mut settled = chest_model().unwrap();
    settled.advance(0.1);
    for (level, lo, hi) in [(4, 219.0, 232.0), (6, 346.0, 480.0)] {
        let params = LocalLoopParams {
            max_level: level,
            ..LocalLoopParams::default()
        };
        let run = run_chest_cut(settled.clone(), params, StepClock(Cell::new(0.0)), 60, 0.0);
        assert!(run.after.nodes > run.before.nodes, "the incision cut");
        let mut free: Vec<usize> = run.loops.iter().map(|l| l.free_nodes).collect();
        assert!(run.loops.iter().all(|l| l.level == level));
        free.sort_unstable();
        let median = free[free.len() / 2] as f64;
        eprintln!(
            "level {level}: {}–{}, median {median}",
            free[0],
            free[free.len() - 1]
        );
        let off = outside(median, lo, hi);
        assert!(
            off <= 0.30,
            "level {level}: median {median} vs {lo}–{hi} ({:.0} % off)",
            off * 100.0
        );
    }
}
