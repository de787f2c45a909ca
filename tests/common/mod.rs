//! Helpers shared by the end-to-end tests: run the `incise` binary, scratch folders, text.
#![allow(dead_code)]

/// The tissue and cut-surface masks, shared with the renderer's tests.
#[path = "../../crates/xr/tests/common/masks.rs"]
pub mod masks;
pub mod pixels;
pub mod xr_report;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub mod monado;

/// Run the built `incise` binary from the workspace root with `args`.
pub fn incise(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_incise"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("incise binary runs")
}

/// A fresh, empty scratch folder unique to this test process and `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("incise-e2e-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create scratch folder");
    d
}

/// A copy of the shipped `config/NAME` in the scratch folder `folder` (see [`temp_dir`])
/// with `scheme` (RON: `Xpbd`, `Newton(())`) named first in its solver; the tool and
/// preset files it names come from the built-in config/ tree.
pub fn scene_on_scheme(name: &str, scheme: &str, folder: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    let text = std::fs::read_to_string(root.join(name)).expect("a shipped scene");
    let key = "    solver: (";
    assert!(text.contains(key), "{name} has no solver");
    let path = temp_dir(folder).join(name);
    std::fs::write(
        &path,
        text.replacen(key, &format!("{key}scheme: {scheme}, "), 1),
    )
    .expect("write the scene copy");
    path
}

/// Command output bytes as text.
pub fn text(o: &[u8]) -> String {
    String::from_utf8_lossy(o).into_owned()
}

/// A `Command` for the built `incise` binary in the workspace root (to spawn and kill).
pub fn incise_command(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_incise"));
    c.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// `incise exercise EXERCISE --stroke STROKE --device cpu --quiet --out OUT --history
/// HISTORY`, which must succeed; its output (result.json, report.json, … are in `out`).
pub fn score_stroke(exercise: &str, stroke: &Path, out: &Path, history: &Path) -> Output {
    let o = incise(&[
        "exercise",
        exercise,
        "--stroke",
        stroke.to_str().unwrap(),
        "--device",
        "cpu",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--history",
        history.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    o
}
