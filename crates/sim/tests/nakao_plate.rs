//! The Nakao 2003 plate experiment (PHYSICS.md §2.6): counts after the reference cut,
//! cut-surface area adaptive vs non-adaptive, and the wound opening against tension.
//!
//! All runs share one computation (the non-adaptive runs take tens of seconds each: their
//! sliver tets hold tiny masses and force small explicit steps).

use std::sync::OnceLock;

use incise_sim::nakao_cut::invariants::check;
use incise_sim::nakao_cut::{PlateCutResult, PlateCutSetup, Subdivision, run_plate_cut};

/// Tensions of the paper's Fig. 11/12.
const TENSIONS: [f64; 3] = [0.02, 0.04, 0.06];

struct Runs {
    adaptive: Vec<PlateCutResult>,
    non_adaptive: Vec<PlateCutResult>,
    untensioned: PlateCutResult,
}

fn run(setup: PlateCutSetup) -> PlateCutResult {
    let (result, model) = run_plate_cut(&setup).expect("plate model builds");
    if let Err(e) = check(&model) {
        panic!("{setup:?}: topology invariant broken: {e}");
    }
    result
}

fn runs() -> &'static Runs {
    static RUNS: OnceLock<Runs> = OnceLock::new();
    RUNS.get_or_init(|| {
        std::thread::scope(|scope| {
            let na: Vec<_> = TENSIONS
                .iter()
                .map(|&s| {
                    scope.spawn(move || run(PlateCutSetup::reference(s, Subdivision::NonAdaptive)))
                })
                .collect();
            let adaptive = TENSIONS
                .iter()
                .map(|&s| run(PlateCutSetup::reference(s, Subdivision::Adaptive)))
                .collect();
            // Without tension nothing pulls the sides apart; a short settle suffices.
            let mut zero = PlateCutSetup::reference(0.0, Subdivision::Adaptive);
            zero.settle_after = 0.05;
            let untensioned = run(zero);
            Runs {
                adaptive,
                non_adaptive: na.into_iter().map(|h| h.join().unwrap()).collect(),
                untensioned,
            }
        })
    })
}

/// Paper: 1,274 nodes / 3,647 tets before, 1,505 / 4,301 after. Our structured plate has
/// 1,250 / 3,456 before (2 % and 5 % fewer); the adaptive cut moves nodes onto the blade's
/// path, so it adds fewer nodes than the paper's did, but both counts land within 15 %.
#[test]
fn counts_after_the_reference_cut_are_in_the_papers_range() {
    let r = &runs().adaptive[1];
    eprintln!("before {:?}\nafter {:?}", r.before, r.after);
    assert_eq!((r.before.nodes, r.before.tets), (1_250, 3_456));
    for (name, got, paper) in [
        ("nodes", r.after.nodes, 1_505.0),
        ("tets", r.after.tets, 4_301.0),
    ] {
        let rel = (got as f64 - paper) / paper;
        assert!(
            rel.abs() <= 0.15,
            "{name}: {got} vs the paper's {paper} ({:+.1} %)",
            rel * 100.0
        );
    }
    assert!(r.after.nodes > r.before.nodes && r.after.tets > r.before.tets);
    assert!(
        r.after.triangles > r.before.triangles,
        "the cut adds surface"
    );
}

#[test]
fn adaptive_cut_surface_is_smaller_than_non_adaptive_for_each_tension() {
    let runs = runs();
    for (a, n) in runs.adaptive.iter().zip(&runs.non_adaptive) {
        eprintln!(
            "s = {}: adaptive {:.3} cm², non-adaptive {:.3} cm²",
            a.setup.tension,
            a.cut_area * 1e4,
            n.cut_area * 1e4
        );
        assert!(a.cut_area > 0.0);
        assert!(
            a.cut_area < n.cut_area,
            "s = {}: adaptive {} m² is not below non-adaptive {} m²",
            a.setup.tension,
            a.cut_area,
            n.cut_area
        );
    }
}

#[test]
fn opening_grows_strictly_with_tension_and_vanishes_without() {
    let runs = runs();
    let widths: Vec<f64> = runs.adaptive.iter().map(|r| r.opening_width).collect();
    eprintln!(
        "opening: none {:.4} mm, {:?} mm",
        runs.untensioned.opening_width * 1e3,
        widths.iter().map(|w| w * 1e3).collect::<Vec<_>>()
    );
    assert!(
        runs.untensioned.opening_width < 1e-6,
        "{}",
        runs.untensioned.opening_width
    );
    assert!(
        widths[0] > 1e-3,
        "2 % tension opens the wound by more than 1 mm"
    );
    assert!(widths.windows(2).all(|w| w[1] > w[0]), "{widths:?}");
    // The wound has settled: no motion left.
    for r in &runs.adaptive {
        assert!(r.final_kinetic_energy < 1e-9, "{}", r.final_kinetic_energy);
    }
}

/// Issue 21, the added counts (paper: +231 nodes, +654 tets at the reference cut). The
/// non-adaptive split, which cuts at every crossing as the paper's counts imply, adds the
/// paper's nodes within 15 %; the adaptive cut snaps nodes onto the blade's path and adds
/// fewer. Both add 1.5–2.2 tets per node (every split point is duplicated, every crossed tet
/// becomes 4 or 6), where the paper's 654 / 231 = 2.83: its tet count is not reachable by
/// its own rule on this plate (docs/experiments/nakao/added_counts.md).
#[test]
fn added_counts_against_the_papers() {
    let runs = runs();
    let added = |r: &PlateCutResult| {
        (
            (r.after.nodes - r.before.nodes) as f64,
            (r.after.tets - r.before.tets) as f64,
        )
    };
    let (n, t) = added(&runs.non_adaptive[1]);
    eprintln!("non-adaptive: +{n} nodes, +{t} tets");
    assert!(
        ((n - 231.0) / 231.0).abs() <= 0.15,
        "non-adaptive adds {n} nodes vs 231"
    );
    let (an, at) = added(&runs.adaptive[1]);
    eprintln!("adaptive: +{an} nodes, +{at} tets");
    assert!(an < n, "snapping adds fewer nodes ({an} vs {n})");
    for (nodes, tets) in [(n, t), (an, at)] {
        let ratio = tets / nodes;
        assert!(
            (1.5..=2.2).contains(&ratio),
            "{tets} tets per {nodes} nodes = {ratio:.2}"
        );
    }
}
