//! End-to-end checks of `incise experiment rheology` that need no long run: a missing or
//! bad preset file exits 1 with a message naming the file, line and field, and writes no
//! figures.

use std::path::PathBuf;
use std::process::{Command, Output};

fn incise(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_incise"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("incise binary runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("incise-rheo-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn missing_preset_file_is_a_clear_error() {
    let out = temp_dir("missing");
    let o = incise(&[
        "experiment",
        "rheology",
        "--out",
        out.to_str().unwrap(),
        "--presets",
        "config/no_such_file.ron",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("config/no_such_file.ron"), "{err}");
}

#[test]
fn out_of_range_preset_names_file_line_and_field() {
    let dir = temp_dir("bad");
    let shipped = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config/rheology.ron"),
    )
    .unwrap();
    let bad = shipped.replacen("density: 1000.0", "density: -1.0", 1);
    assert_ne!(bad, shipped);
    let file = dir.join("bad.ron");
    std::fs::write(&file, bad).unwrap();
    let o = incise(&[
        "experiment",
        "rheology",
        "--out",
        dir.join("out").to_str().unwrap(),
        "--presets",
        file.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bad.ron:") && err.contains("\"elastic\": density"),
        "{err}"
    );
    assert!(!dir.join("out/creep.png").exists());
}
