//! Issue 20: every method runs through the one `SimBody` interface and frame loop of
//! `incise run`, its report has the shared schema with a `method` field, and each
//! checks the method's own result: XPBD releases tets along the scalpel's stroke, the
//! Nakao cutter adds nodes and tets and the wound opens under the tension, the
//! rheological body is pressed to the indenter's depth and creeps back after the lift.

mod common;

use std::path::Path;

use common::{incise, temp_dir, text};

/// Run `scene` for `frames` frames (all: `None`) into `out`; its report.
fn run(scene: &str, frames: Option<u64>, out: &Path) -> serde_json::Value {
    let frames = frames.map(|f| f.to_string());
    let mut args = vec![
        "run",
        scene,
        "--quiet",
        "--vtu-every",
        "0",
        "--device",
        "cpu",
    ];
    if let Some(f) = &frames {
        args.extend(["--frames", f.as_str()]);
    }
    args.extend(["--out", out.to_str().unwrap()]);
    let o = incise(&args);
    assert!(o.status.success(), "{scene}: {}", text(&o.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["status"], "completed", "{scene}");
    // The shared schema: the same top-level fields whatever the method.
    for key in [
        "scene", "model", "method", "mesh", "solver", "device", "frames",
    ] {
        assert!(report.get(key).is_some(), "{scene}: report lacks {key}");
    }
    report
}

/// Frame `key` of every frame of `report`.
fn series(report: &serde_json::Value, key: &str) -> Vec<f64> {
    report["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            f[key]
                .as_f64()
                .unwrap_or_else(|| panic!("frame lacks {key}: {f}"))
        })
        .collect()
}

#[test]
fn xpbd_scalpel_stroke_releases_tets() {
    let report = run("config/plate_cut.ron", Some(60), &temp_dir("m-xpbd"));
    assert_eq!(report["method"], "xpbd");
    let released = report["released_tets"].as_array().unwrap().len();
    let counted = series(&report, "released_total");
    assert!(released > 50, "the blade released {released} tets");
    assert_eq!(*counted.last().unwrap() as usize, released);
}

#[test]
fn nakao_cut_adds_nodes_and_tets_and_the_wound_opens() {
    let report = run("config/plate_cut_nakao.ron", Some(60), &temp_dir("m-nakao"));
    assert_eq!(report["method"], "nakao");
    assert_eq!(report["model"], "mass-spring");
    let n = &report["nakao"];
    let (nodes, tets) = (
        n["nodes_added"].as_u64().unwrap(),
        n["tets_added"].as_u64().unwrap(),
    );
    // The blade runs 0.4 s of its 0.7 s stroke across the 1250-node plate.
    assert!(nodes > 40 && tets > 80, "{n}");
    assert_eq!(
        report["mesh"]["nodes"].as_u64().unwrap(),
        1250 + nodes,
        "{n}"
    );
    // Under 4 % tension the two sides of the cut part: a wound of millimetres, not the
    // micrometres of a cut that stayed shut.
    let width = n["opening_width_m"].as_f64().unwrap();
    assert!(width > 5e-4 && width < 2e-2, "opening {width} m");
    assert!(n["cut_area_m2"].as_f64().unwrap() > 0.0, "{n}");
}

#[test]
fn rheology_press_reaches_the_indenter_depth_and_creeps_back() {
    let report = run("config/organ_layers.ron", None, &temp_dir("m-rheology"));
    assert_eq!(report["method"], "rheology");
    let (depth, dent, t) = (
        series(&report, "indenter_depth"),
        series(&report, "dent_depth"),
        series(&report, "sim_time"),
    );
    // Pressed 3 cm for 0.5 s, held 0.5 s: the probe node follows the face down.
    let deepest = depth.iter().copied().fold(0.0, f64::max);
    let max_dent = dent.iter().copied().fold(0.0, f64::max);
    assert!((deepest - 0.03).abs() < 1e-6, "indenter {deepest} m");
    assert!((max_dent - 0.03).abs() < 1e-3, "dent {max_dent} m");
    // After the lift (1.1 s) the dent creeps back: never deeper again, and by the end
    // it has recovered a good part of the press but kept a residual (rheological core).
    let lifted = t.iter().position(|&t| t > 1.15).unwrap();
    let after = &dent[lifted..];
    assert!(
        after.windows(2).all(|w| w[1] <= w[0] + 1e-5),
        "the dent grew after the lift: {after:?}"
    );
    let (at_lift, end) = (after[0], *after.last().unwrap());
    assert!(
        end < 0.8 * at_lift,
        "crept back from {at_lift} m to {end} m only"
    );
    assert!(end > 1e-4, "no residual dent: {end} m");
    assert_eq!(report["rheology"]["residual_dent_m"].as_f64().unwrap(), end);
}

/// A stroke file drives the Nakao blade as a hand would (the shipped plate exercise's
/// reference stroke: the blade upright along an 8 cm line), in place of the scene's
/// scripted 14 cm cut; a rheology scene refuses it, saying what it drives.
#[test]
fn a_stroke_file_drives_the_nakao_blade_and_rheology_refuses_it() {
    let dir = temp_dir("methods-run-stroke");
    let stroke =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("config/strokes/plate_line_nakao_reference.ron");
    let out = dir.join("nakao");
    let o = incise(&[
        "run",
        "config/plate_cut_nakao.ron",
        "--stroke",
        stroke.to_str().unwrap(),
        "--frames",
        "341",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    // The stroke's line runs from x = -4 to +4 cm; the scene's own cut from -7 to +7 cm.
    let frames = r["frames"].as_array().unwrap();
    let touching = frames.iter().filter(|f| f["blade_contact"] == true).count();
    assert!(
        touching > 250,
        "{touching} frames with the blade in the plate"
    );
    let force = frames
        .iter()
        .filter_map(|f| f["tool_force"].as_array())
        .count();
    assert_eq!(
        force,
        frames.len(),
        "a hand-held blade reports its force every frame"
    );
    let cut_area = r["nakao"]["cut_area_m2"].as_f64().unwrap();
    // Both sides of an 8 cm × 4 mm wound: 6.4 cm²; the scene's 14 cm cut would be 11 cm².
    assert!((5e-4..8e-4).contains(&cut_area), "cut area {cut_area} m²");
    let o = incise(&[
        "run",
        "config/organ_layers.ron",
        "--stroke",
        stroke.to_str().unwrap(),
        "--out",
        dir.join("rheology").to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "a rheology scene took a stroke file");
    let err = text(&o.stderr);
    assert!(
        err.contains("--stroke is for the XPBD scalpel and the Nakao blade"),
        "{err}"
    );
}
