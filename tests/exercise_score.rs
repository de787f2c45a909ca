//! Unit tests of the exercise scoring (src/exercise/score.rs `judge`) and metrics
//! (src/exercise/metrics.rs `compute`) on hand-made inputs with known answers, no
//! simulation: the shipped slab_depth exercise, its slab at rest, tets released by
//! hand and tool frames made up (docs/scoring.md has the formulas).

use std::path::Path;

use glam::{DVec3, Vec3};
use incise::exercise::{LoadedExercise, Metrics, ToolFrame, compute_metrics, judge, load_exercise};
use incise::sim_body::{RestCut, RestCutFace};
use incise_sim::xpbd::FrameStats;

fn slab_depth() -> LoadedExercise {
    load_exercise(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/exercises/slab_depth.ron"))
        .unwrap()
}

/// An attempt that meets every target exactly (slab_depth's limits: lateral 3 mm, depth
/// 3 ± 2.5 mm, 3 N, 4 s).
fn perfect() -> Metrics {
    Metrics {
        plan_length: 0.03,
        tet_edge: 0.0025,
        released_tets: 100,
        trace_faces: 40,
        mean_deviation: Some(0.0),
        max_deviation: Some(0.0),
        completion: 1.0,
        mean_depth_error: Some(0.0),
        max_depth: 0.003,
        collateral_volume: 0.0,
        released_volume: 1e-7,
        cut_faces: 0,
        cut_area: 0.0,
        band_volume: 0.03 * 2.0 * 0.003 * 0.0055,
        max_force: 1.0,
        mean_force: 0.5,
        strokes: 1,
        duration: 2.0,
        depth_profile: Vec::new(),
        force_series: Vec::new(),
    }
}

fn check<'a>(v: &'a incise::exercise::Verdict, name: &str) -> &'a incise::exercise::Check {
    v.checks.iter().find(|c| c.name == name).unwrap()
}

#[test]
fn a_perfect_attempt_scores_100_and_passes_every_check() {
    let ex = slab_depth();
    let v = judge(&ex.exercise, &perfect());
    assert!((v.score - 100.0).abs() < 1e-9, "{}", v.score);
    assert!(
        v.passed && v.checks.iter().all(|c| c.passed),
        "{:?}",
        v.checks
    );
    assert_eq!(v.checks.len(), 9);
}

#[test]
fn each_part_loses_points_in_proportion_to_its_tolerance() {
    let ex = slab_depth();
    // Half the lateral tolerance off the plan: half the 20 deviation points.
    let m = Metrics {
        mean_deviation: Some(0.0015),
        max_deviation: Some(0.005),
        ..perfect()
    };
    let v = judge(&ex.exercise, &m);
    assert!((v.parts.deviation - 10.0).abs() < 1e-6, "{:?}", v.parts);
    assert!((v.score - 90.0).abs() < 1e-6);
    assert!(!check(&v, "max_deviation").passed, "5 mm > 4 mm allowed");
    assert!(check(&v, "mean_deviation").passed, "1.5 mm ≤ 2 mm allowed");
    assert!(!v.passed);
    // 60 % of the plan: 18 of 30 completion points, and the 90 % condition fails.
    let v = judge(
        &ex.exercise,
        &Metrics {
            completion: 0.6,
            ..perfect()
        },
    );
    assert!((v.parts.completion - 18.0).abs() < 1e-6);
    assert!(!check(&v, "completion").passed);
    // 1.5× the force limit: half the 10 force points.
    let v = judge(
        &ex.exercise,
        &Metrics {
            max_force: 4.5,
            ..perfect()
        },
    );
    assert!((v.parts.force - 5.0).abs() < 1e-6, "{:?}", v.parts);
    assert!(!check(&v, "max_force").passed);
    // Twice the time limit: half the 5 time points.
    let v = judge(
        &ex.exercise,
        &Metrics {
            duration: 8.0,
            ..perfect()
        },
    );
    assert!((v.parts.time - 2.5).abs() < 1e-6);
    assert!(!check(&v, "time").passed);
    // Collateral of half the band: half the 15 points, and more than 100 mm³ fails.
    let m = perfect();
    let v = judge(
        &ex.exercise,
        &Metrics {
            collateral_volume: m.band_volume / 2.0,
            ..m
        },
    );
    assert!((v.parts.collateral - 7.5).abs() < 1e-6);
    assert!(!check(&v, "collateral").passed);
    // Half the 2.5 mm depth tolerance off the target: half the 20 depth points (the
    // depth tolerance, not the 3 mm lateral one), still within the 2.5 mm allowed.
    let v = judge(
        &ex.exercise,
        &Metrics {
            mean_depth_error: Some(0.00125),
            ..perfect()
        },
    );
    assert!((v.parts.depth - 10.0).abs() < 1e-6, "{:?}", v.parts);
    assert!((v.score - 90.0).abs() < 1e-6, "{}", v.score);
    assert!(check(&v, "depth_error").passed);
    assert!(check(&v, "depth_error").detail.contains("1.2 mm"));
    // 3 mm off: no depth points, and the 2.5 mm condition fails.
    let v = judge(
        &ex.exercise,
        &Metrics {
            mean_depth_error: Some(0.003),
            ..perfect()
        },
    );
    assert_eq!(v.parts.depth, 0.0, "{:?}", v.parts);
    assert!(!check(&v, "depth_error").passed);
    // Through the slab: deeper than 3 + 2.5 mm fails max_depth.
    let v = judge(
        &ex.exercise,
        &Metrics {
            max_depth: 0.006,
            ..perfect()
        },
    );
    assert!(!check(&v, "max_depth").passed);
    assert!(check(&v, "max_depth").detail.contains("6.0 mm"));
}

#[test]
fn nothing_cut_scores_no_deviation_or_depth_points_and_says_why() {
    let ex = slab_depth();
    let m = Metrics {
        mean_deviation: None,
        max_deviation: None,
        mean_depth_error: None,
        completion: 0.0,
        duration: 0.0,
        ..perfect()
    };
    let v = judge(&ex.exercise, &m);
    assert_eq!(
        (v.parts.deviation, v.parts.depth, v.parts.completion),
        (0.0, 0.0, 0.0)
    );
    assert!(
        check(&v, "mean_deviation")
            .detail
            .contains("nothing was cut")
    );
    assert!(check(&v, "time").detail.contains("never touched"));
    assert!(!v.passed && !check(&v, "score").passed, "{}", v.score);
}

/// Rest centroid of tet `t`.
fn centroid(ex: &LoadedExercise, t: usize) -> DVec3 {
    ex.mesh.tets[t]
        .iter()
        .map(|&i| ex.mesh.rest_positions[i as usize].as_dvec3())
        .sum::<DVec3>()
        / 4.0
}

#[test]
fn metrics_of_a_hand_made_cut_along_the_plan() {
    let ex = slab_depth();
    let n = ex.mesh.tet_count();
    // Nothing released, no contact.
    let none = compute_metrics(
        &ex.exercise,
        &ex.plan,
        &ex.mesh,
        &RestCut::Released(vec![false; n]),
        &[],
        1.0 / 60.0,
    );
    assert_eq!(
        (none.completion, none.released_tets, none.strokes),
        (0.0, 0, 0)
    );
    assert_eq!((none.mean_deviation, none.duration), (None, 0.0));
    // Release the top layer's tets under the plan (y = 2 cm, x 2.5–5.5 cm, the top
    // 2 mm cell layer of the 8 mm slab): the whole plan cut, on the line, 2 mm deep.
    let on_plan =
        |c: DVec3| (c.y - 0.02).abs() < 0.0015 && (0.025..0.055).contains(&c.x) && c.z > 0.006;
    let released: Vec<bool> = (0..n).map(|t| on_plan(centroid(&ex, t))).collect();
    let m = compute_metrics(
        &ex.exercise,
        &ex.plan,
        &ex.mesh,
        &RestCut::Released(released.clone()),
        &[],
        1.0 / 60.0,
    );
    assert_eq!(m.released_tets, released.iter().filter(|r| **r).count());
    assert!(m.completion > 0.9, "completion {}", m.completion);
    assert!(
        m.mean_deviation.unwrap() < m.tet_edge,
        "{:?}",
        m.mean_deviation
    );
    assert!((m.max_depth - 0.002).abs() < 1e-6, "depth {}", m.max_depth);
    assert!(
        (m.mean_depth_error.unwrap() - 0.001).abs() < 3e-4,
        "{:?}",
        m.mean_depth_error
    );
    assert_eq!(m.collateral_volume, 0.0);
    // The bottom layer under the plan, released from below: its faces on the table side
    // face away from the plan's surface, so they leave no trace on it (nothing of the
    // plan is cut), and 7 mm deep they are all collateral.
    let below =
        |c: DVec3| (c.y - 0.02).abs() < 0.0015 && (0.025..0.055).contains(&c.x) && c.z < 0.002;
    let under: Vec<bool> = (0..n).map(|t| below(centroid(&ex, t))).collect();
    let mb = compute_metrics(
        &ex.exercise,
        &ex.plan,
        &ex.mesh,
        &RestCut::Released(under.clone()),
        &[],
        1.0 / 60.0,
    );
    let under_volume: f64 = (0..n)
        .filter(|&t| under[t])
        .map(|t| ex.mesh.rest_volume[t] as f64)
        .sum();
    assert!(mb.released_tets > 0);
    assert_eq!(
        (mb.trace_faces, mb.completion, mb.mean_deviation),
        (0, 0.0, None),
        "faces on the far side counted as the trace"
    );
    assert!(
        (mb.collateral_volume - under_volume).abs() < 1e-12,
        "{}",
        mb.collateral_volume
    );
    // Tets 1 cm to the side are collateral, volume for volume.
    let aside =
        |c: DVec3| (c.y - 0.03).abs() < 0.0015 && (0.025..0.035).contains(&c.x) && c.z > 0.006;
    let extra: Vec<usize> = (0..n).filter(|&t| aside(centroid(&ex, t))).collect();
    let mut both = released.clone();
    extra.iter().for_each(|&t| both[t] = true);
    let m2 = compute_metrics(
        &ex.exercise,
        &ex.plan,
        &ex.mesh,
        &RestCut::Released(both),
        &[],
        1.0 / 60.0,
    );
    let volume: f64 = extra.iter().map(|&t| ex.mesh.rest_volume[t] as f64).sum();
    assert!(!extra.is_empty());
    assert!(
        (m2.collateral_volume - volume).abs() < 1e-12 * volume.max(1.0),
        "{} vs {volume}",
        m2.collateral_volume
    );
}

#[test]
fn tool_figures_count_strokes_across_contact_gaps() {
    let ex = slab_depth();
    let n = ex.mesh.tet_count();
    // Contact in frames 10–19 and 30–34 (a gap of 10 > 6 frames: two strokes), 2 N
    // peak; frame 25 has a force but no contact.
    let frames: Vec<FrameStats> = (0..40)
        .map(|i| FrameStats {
            frame: i,
            sim_time: i as f64 / 60.0,
            contact_nodes: if (10..20).contains(&i) || (30..35).contains(&i) {
                3
            } else {
                0
            },
            tool_force: Vec3::new(
                0.0,
                0.0,
                match i {
                    15 => 2.0,
                    25 => 0.5,
                    10..20 | 30..35 => 1.0,
                    _ => 0.0,
                },
            ),
            ..FrameStats::default()
        })
        .collect();
    let m = compute_metrics(
        &ex.exercise,
        &ex.plan,
        &ex.mesh,
        &RestCut::Released(vec![false; n]),
        &frames.iter().map(ToolFrame::of_xpbd).collect::<Vec<_>>(),
        0.5,
    );
    assert_eq!(m.strokes, 2);
    assert_eq!(m.max_force, 2.0);
    // Mean over the 15 contact frames: (14 × 1 + 2) / 15.
    assert!(
        (m.mean_force - 16.0 / 15.0).abs() < 1e-9,
        "{}",
        m.mean_force
    );
    // First to last contact, frames 10..=34, 0.5 s each.
    assert!((m.duration - 12.5).abs() < 1e-9, "{}", m.duration);
    assert_eq!(m.force_series.len(), 40);
}

/// A cut surface (a Nakao body's, at rest) read against the plan: a vertical wall 3 mm
/// deep under slab_depth's line is the whole plan cut to depth with no collateral; faces
/// 1 cm aside are collateral, each tet they bound counted once; a face buried 5 mm deep
/// (no corner at the surface) deepens the cut but leaves no trace.
#[test]
fn metrics_of_a_hand_made_cut_surface() {
    let ex = slab_depth();
    let wall = |y: f64, x0: f64, x1: f64, top: f64, bottom: f64, first_tet: u32| {
        let steps = ((x1 - x0) / 0.001).round() as usize;
        (0..steps)
            .flat_map(|k| {
                let (a, b) = (x0 + 0.001 * k as f64, x0 + 0.001 * (k + 1) as f64);
                let p = |x: f64, z: f64| DVec3::new(x, y, z);
                let tet = first_tet + k as u32;
                [
                    [p(a, top), p(b, top), p(a, bottom)],
                    [p(b, top), p(b, bottom), p(a, bottom)],
                ]
                .map(|corners| RestCutFace {
                    corners,
                    tet,
                    tet_volume: 1e-9,
                })
            })
            .collect::<Vec<_>>()
    };
    let metrics = |faces: Vec<RestCutFace>| {
        compute_metrics(
            &ex.exercise,
            &ex.plan,
            &ex.mesh,
            &RestCut::Faces(faces),
            &[],
            1.0 / 60.0,
        )
    };
    let on_plan = wall(0.02, 0.025, 0.055, 0.008, 0.005, 0);
    let m = metrics(on_plan.clone());
    assert!(m.completion > 0.99, "completion {}", m.completion);
    assert_eq!((m.cut_faces, m.trace_faces, m.released_tets), (60, 60, 0));
    assert!((m.max_depth - 0.003).abs() < 1e-9, "depth {}", m.max_depth);
    // Face centroids lie up to half a sample spacing (0.25 mm) along the plan from a sample.
    let (dev, depth_err) = (m.mean_deviation.unwrap(), m.mean_depth_error.unwrap());
    assert!(
        depth_err < 1e-9 && dev < 3e-4,
        "deviation {dev}, depth error {depth_err}"
    );
    assert!(
        (m.cut_area - 0.03 * 0.003).abs() < 1e-9,
        "area {}",
        m.cut_area
    );
    assert_eq!(m.collateral_volume, 0.0);
    // Ten faces 1 cm aside, two per tet: five tets of 1e-9 m³ each.
    let mut aside = on_plan.clone();
    aside.extend(wall(0.03, 0.030, 0.035, 0.008, 0.005, 100));
    let m = metrics(aside);
    assert!(
        (m.collateral_volume - 5e-9).abs() < 1e-15,
        "{}",
        m.collateral_volume
    );
    assert!(m.max_deviation.unwrap() > 0.009, "{:?}", m.max_deviation);
    // Buried 4–5 mm deep under the first centimetre: deeper there, no new trace.
    let mut buried = on_plan;
    buried.extend(wall(0.02, 0.025, 0.035, 0.004, 0.003, 200));
    let m = metrics(buried);
    assert_eq!(m.trace_faces, 60, "a buried face counted in the trace");
    assert!((m.max_depth - 0.005).abs() < 1e-9, "depth {}", m.max_depth);
}
