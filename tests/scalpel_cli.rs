//! The scalpel from the command line (issue 5): a scripted incision cuts along the blade
//! and reports the tool force; a recorded stroke replays the same cut; bad tool and
//! stroke files are errors naming the file and field.

mod common;

use common::{incise, temp_dir, text};
use serde_json::Value;

fn report(dir: &std::path::Path) -> Value {
    let s = std::fs::read_to_string(dir.join("report.json")).expect("report.json");
    serde_json::from_str(&s).expect("report.json parses")
}

fn released(r: &Value) -> Vec<u64> {
    r["released_tets"]
        .as_array()
        .expect("released_tets")
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect()
}

/// 120 frames of `config/plate_cut.ron` on the CPU into `out`, recording (`--record-stroke`)
/// or replaying (`--stroke`) `stroke`.
fn cut_plate(out: &std::path::Path, flag: &str, stroke: &std::path::Path) {
    let o = incise(&[
        "run",
        "config/plate_cut.ron",
        "--device",
        "cpu",
        "--frames",
        "120",
        "--vtu-every",
        "0",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        flag,
        stroke.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn scripted_incision_cuts_reports_force_and_replays_exactly() {
    let dir = temp_dir("scalpel-incision");
    let first = dir.join("first");
    let rec = dir.join("stroke.ron");
    cut_plate(&first, "--record-stroke", &rec);
    let r = report(&first);
    assert_eq!(r["tool"]["name"], "scalpel_10");
    let cut = released(&r);
    assert!(cut.len() > 50, "the blade released only {} tets", cut.len());
    let frames = r["frames"].as_array().unwrap();
    let peak = frames
        .iter()
        .map(|f| f["tool_force"][2].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(
        peak > 0.05,
        "the tissue never pushed back on the blade ({peak} N)"
    );
    let amp = frames
        .iter()
        .map(|f| f["haptic_amplitude"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(amp > 0.0 && amp <= 1.0, "haptic amplitude {amp}");
    // Replay the recorded stroke: the same tets, bit for bit.
    let second = dir.join("second");
    cut_plate(&second, "--stroke", &rec);
    assert_eq!(
        released(&report(&second)),
        cut,
        "the replay released other tets"
    );
}

#[test]
fn bad_strokes_and_tools_are_errors_naming_the_field() {
    let dir = temp_dir("scalpel-bad");
    let stroke = dir.join("bad.ron");
    std::fs::write(
        &stroke,
        "(poses: [\n  (t: 0.0, position: (0.0, 0.0, 0.1), rotation: (0.0, 0.0, 0.0, 1.0)),\n  (t: 0.0, position: (0.0, 0.0, 0.0), rotation: (0.0, 0.0, 0.0, 1.0)),\n])\n",
    )
    .unwrap();
    let o = incise(&[
        "run",
        "config/plate_cut.ron",
        "--frames",
        "1",
        "--quiet",
        "--out",
        dir.join("o").to_str().unwrap(),
        "--stroke",
        stroke.to_str().unwrap(),
    ]);
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("bad.ron") && err.contains("poses[1]"), "{err}");
    // A scene whose tool file has a negative sphere radius.
    let tools = dir.join("tools");
    std::fs::create_dir_all(&tools).unwrap();
    let good = std::fs::read_to_string("config/tools/scalpel_10.ron").unwrap();
    let bad = good.replace(
        "spheres: FromTissue(radius_factor: 0.5, spacing_factor: 1.5)",
        "spheres: Fixed(count: 8, radius: -1.0)",
    );
    assert_ne!(
        bad, good,
        "the preset's sphere line changed; update this test"
    );
    std::fs::write(tools.join("scalpel_10.ron"), bad).unwrap();
    std::fs::copy("config/materials.ron", dir.join("materials.ron")).unwrap();
    std::fs::copy("config/plate_cut.ron", dir.join("scene.ron")).unwrap();
    let o = incise(&[
        "run",
        dir.join("scene.ron").to_str().unwrap(),
        "--frames",
        "1",
        "--quiet",
        "--out",
        dir.join("o2").to_str().unwrap(),
    ]);
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("scalpel_10.ron") && err.contains("radius"),
        "{err}"
    );
}
