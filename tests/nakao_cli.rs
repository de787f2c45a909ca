//! End-to-end tests of the mass-spring parts of the `incise` binary: a `MassSpring` scene
//! runs and reports, a bad model field is named with its line, and the loop benchmark
//! prints its JSON.

mod common;

use common::{incise, temp_dir, text};

#[test]
fn shipped_nakao_scene_cuts_and_reports() {
    let out = temp_dir("scene");
    let o = incise(&[
        "run",
        "config/plate_cut_nakao.ron",
        "--frames",
        "60",
        "--vtu-every",
        "30",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["status"], "completed");
    assert_eq!(report["device"], "cpu (mass-spring)");
    let frames = report["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 60);
    for key in [
        "sim_time",
        "substeps",
        "kinetic_energy",
        "volume_ratio",
        "wall_ms",
    ] {
        assert!(frames[0].get(key).is_some(), "frame record lacks {key}");
    }
    // The blade starts at 0.2 s and runs 0.4 s in these 0.6 s: the mesh has grown.
    assert!(report["mesh"]["nodes"].as_u64().unwrap() > 1_250);
    assert!(report["mesh"]["tets"].as_u64().unwrap() > 3_456);
    assert!(out.join("run.pvd").exists() && out.join("snap_00060.vtu").exists());
}

#[test]
fn bad_model_field_names_file_line_and_field() {
    let dir = temp_dir("bad");
    let scene = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/plate_cut_nakao.ron"),
    )
    .unwrap()
    .replace("tension: Uniform(0.04)", "tension: Uniform(1.5)");
    let path = dir.join("bad.ron");
    std::fs::write(&path, scene).unwrap();
    let o = incise(&[
        "run",
        path.to_str().unwrap(),
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(
        err.contains("bad.ron:") && err.contains("model.tension"),
        "{err}"
    );
}

#[test]
fn loop_benchmark_prints_json() {
    let o = incise(&["experiment", "nakao-bench", "--loops", "20", "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["mesh"][1], 72_000);
    let cases: Vec<&str> = v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["case"].as_str().unwrap())
        .collect();
    assert!(
        cases.contains(&"level 4") && cases.contains(&"full mesh"),
        "{cases:?}"
    );
}
