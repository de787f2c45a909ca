//! Clean output (issue 34 item 3): a command that succeeds prints no `error:` line, in
//! any mode, with or without `XDG_RUNTIME_DIR` (Xvfb, ssh and CI sessions have none; Mesa's
//! Vulkan device-select layer then printed "error: XDG_RUNTIME_DIR is invalid or not set"
//! twice when asked for Wayland surfaces).
//!
//! The preview needs `xvfb-run` and a wgpu adapter: without them that part prints why and
//! passes, unless required (`INCISE_REQUIRE_GPU=1`, or `CI` set).

mod common;

use std::process::{Command, Output};

use common::{incise_command, temp_dir, text};
use incise_test_gate::{Need, skip_or_fail};

/// Lines of `o`'s stdout and stderr that start with `error:` (any case).
fn error_lines(o: &Output) -> Vec<String> {
    let all = format!("{}\n{}", text(&o.stdout), text(&o.stderr));
    all.lines()
        .filter(|l| l.trim_start().to_lowercase().starts_with("error:"))
        .map(String::from)
        .collect()
}

/// `cmd` run without `XDG_RUNTIME_DIR` from the workspace root: it succeeds and prints no
/// `error:` line.
fn assert_clean(what: &str, mut cmd: Command) -> Output {
    let o = cmd
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .expect("the command runs");
    assert!(o.status.success(), "{what} failed: {}", text(&o.stderr));
    let errors = error_lines(&o);
    assert!(errors.is_empty(), "{what} succeeded but printed {errors:?}");
    o
}

#[test]
fn the_preview_without_xdg_runtime_dir_prints_no_error() {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        skip_or_fail(Need::Gpu, "xvfb-run is not installed");
        return;
    }
    let mut cmd = Command::new("xvfb-run");
    cmd.args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_incise"))
        .args(["preview", "config/plate_cut.ron", "--frames", "3"])
        .args(["--size", "320x240"]);
    let o = assert_clean("incise preview under Xvfb", cmd);
    assert!(text(&o.stdout).contains("preview of plate_cut: 3 frames"));
}

#[test]
fn headless_commands_without_xdg_runtime_dir_print_no_error() {
    let dir = temp_dir("clean-output");
    let out = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let (run, png, xr) = (out("run"), out("plate.png"), out("xr"));
    assert_clean(
        "incise run",
        incise_command(&[
            "run",
            "config/plate_cut.ron",
            "--frames",
            "3",
            "--out",
            &run,
        ]),
    );
    assert_clean(
        "incise render",
        incise_command(&["render", "config/plate_cut.ron", &png]),
    );
    assert_clean(
        "incise xr --simulated-headset",
        incise_command(&[
            "xr",
            "config/plate_cut.ron",
            "--simulated-headset",
            "config/xr/plate_cut_headset.ron",
            "--frames",
            "5",
            "--out",
            &xr,
        ]),
    );
}

#[test]
fn an_error_line_is_seen() {
    let o = Command::new("sh")
        .args([
            "-c",
            "echo ok; echo 'error: XDG_RUNTIME_DIR is invalid' >&2",
        ])
        .output()
        .unwrap();
    assert_eq!(error_lines(&o), ["error: XDG_RUNTIME_DIR is invalid"]);
}
