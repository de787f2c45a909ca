//! End-to-end checks of `incise experiment rheology` that need no long run: a missing or
//! bad preset file exits 1 with a message naming the file, line and field, and writes no
//! figures.

mod common;

use common::{incise, temp_dir};

use std::path::PathBuf;

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
