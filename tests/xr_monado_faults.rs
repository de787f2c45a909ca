//! The XR session's failure paths against Monado (issue 19, item 4), with an OpenXR API
//! layer built here (tests/xr_fault_layer/fault_layer.c) between incise and the runtime:
//! Ctrl-C before the session is ready and while it is FOCUSED, `xrCreateInstance`
//! failures of a runtime that was found, runtime manifests that cannot be used, and a
//! runtime whose tested Vulkan version is below the one incise asks for.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use common::monado::{self, Spawned, Validation};
use common::{temp_dir, text};

const SCENE: &str = "config/plate_cut.ron";
/// The layer's name in its manifest.
const LAYER: &str = "XR_APILAYER_INCISE_fault";
/// No validation layers: the fault layer is the only one.
const NONE: Validation = Validation {
    xr: false,
    vulkan: false,
};

/// Build the fault layer into `dir` with Monado's bundled OpenXR headers; the folder to
/// put on `XR_API_LAYER_PATH`.
fn build_layer(manifest: &Path, dir: &Path) -> PathBuf {
    let layers = dir.join("layers");
    std::fs::create_dir_all(&layers).unwrap();
    let lib = layers.join("libincise_fault_layer.so");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/xr_fault_layer/fault_layer.c");
    let o = Command::new("cc")
        .args(["-shared", "-fPIC", "-O1", "-Wall", "-Werror", "-I"])
        .arg(monado::openxr_includes(manifest))
        .arg(&src)
        .arg("-o")
        .arg(&lib)
        .output()
        .expect("cc runs (build-essential)");
    assert!(
        o.status.success(),
        "building the layer: {}",
        text(&o.stderr)
    );
    let json = format!(
        r#"{{"file_format_version": "1.0.0", "api_layer": {{"name": "{LAYER}", "library_path": "{}", "api_version": "1.0", "implementation_version": "1", "description": "incise test faults"}}}}"#,
        lib.display()
    );
    std::fs::write(layers.join("incise_fault.json"), json).unwrap();
    layers
}

/// `incise xr ARGS` on Monado with the fault layer playing `fault`.
fn faulty(manifest: &Path, dir: &Path, fault: &str, args: &[&str]) -> Command {
    let layers = build_layer(manifest, dir);
    let mut c = monado::command(manifest, dir, args, NONE);
    c.env("XR_API_LAYER_PATH", layers)
        .env("XR_ENABLE_API_LAYERS", LAYER)
        .env("INCISE_XR_FAULT", fault);
    c
}

fn xr_args<'a>(out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "xr",
        SCENE,
        "--device",
        "cpu",
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    a
}

#[test]
fn ctrl_c_before_the_runtime_makes_the_session_ready_stops_at_once() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let dir = temp_dir("xr-fault-never-ready");
    let out = dir.join("out");
    let mut p = Spawned::new(faulty(manifest, &dir, "never-ready", &xr_args(&out, &[])));
    assert!(
        p.wait_for("READY withheld", Duration::from_secs(60)),
        "the layer never withheld READY:\n{}",
        p.stderr.join("\n")
    );
    // Let the loop idle a moment, then Ctrl-C.
    std::thread::sleep(Duration::from_millis(500));
    let sent = Instant::now();
    p.interrupt();
    let code = p.exit_within(Duration::from_secs(8));
    let waited = sent.elapsed();
    let err = p.stderr.join("\n");
    assert_eq!(code, Some(130), "after {waited:?}:\n{err}");
    assert!(waited < Duration::from_secs(3), "took {waited:?} to stop");
    assert!(err.contains("interrupted after 0 frames"), "{err}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("xr_report.json")).unwrap())
            .unwrap();
    assert_eq!(r["exit"], "Interrupted", "{r}");
    assert_eq!(r["session_states"], serde_json::json!(["Idle"]), "{r}");
    assert_eq!(r["frames"].as_u64(), Some(0), "{r}");
}

#[test]
fn ctrl_c_while_focused_ends_the_session_through_the_runtime_and_exits_130() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let dir = temp_dir("xr-fault-ctrl-c");
    let out = dir.join("out");
    let args = xr_args(&out, &["--frames", "100000"]);
    let mut p = Spawned::new(monado::command(manifest, &dir, &args, NONE));
    assert!(
        p.wait_for("xr: session Focused", Duration::from_secs(60)),
        "never FOCUSED:\n{}",
        p.stderr.join("\n")
    );
    std::thread::sleep(Duration::from_millis(500));
    p.interrupt();
    let code = p.exit_within(Duration::from_secs(20));
    let err = p.stderr.join("\n");
    assert_eq!(code, Some(130), "{err}");
    assert!(err.contains("interrupted after"), "{err}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("xr_report.json")).unwrap())
            .unwrap();
    assert_eq!(r["exit"], "Interrupted", "{r}");
    // Ended the way the runtime expects: xrRequestExitSession, then STOPPING … EXITING.
    let states = r["session_states"].as_array().unwrap();
    assert_eq!(states.last().unwrap(), "Exiting", "{r}");
    assert!(states.iter().any(|s| s == "Stopping"), "{r}");
    assert!(r["frames"].as_u64().unwrap() > 0, "{r}");
    assert!(out.join("frames.csv").is_file());
    // (A stroke needs two simulation frames; a Ctrl-C at once may leave only one.)
    let sim = r["sim_frames"].as_u64().unwrap();
    assert_eq!(out.join("stroke.ron").is_file(), sim >= 2, "{r}");
}

fn output(mut c: Command) -> Output {
    c.output().expect("incise runs")
}

#[test]
fn an_instance_the_found_runtime_fails_to_create_is_named_with_what_to_do() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let cases = [
        (
            -2,
            "XR_ERROR_RUNTIME_FAILURE",
            "failed inside xrCreateInstance",
        ),
        (-3, "XR_ERROR_OUT_OF_MEMORY", "ran out of memory"),
        (-6, "XR_ERROR_INITIALIZATION_FAILED", "could not initialise"),
        (-13, "XR_ERROR_INSTANCE_LOST", "shutting down or restarting"),
    ];
    for (code, name, what) in cases {
        let dir = temp_dir(&format!("xr-fault-create{code}"));
        let out = dir.join("out");
        let o = output(faulty(
            manifest,
            &dir,
            &format!("create:{code}"),
            &xr_args(&out, &[]),
        ));
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        let line = err
            .lines()
            .find(|l| l.starts_with("error: "))
            .unwrap_or_else(|| panic!("{name}: no error line in {err}"));
        assert!(line.contains(name) && line.contains(what), "{line}");
        // The runtime was found: the message names its manifest, never "no runtime".
        assert!(
            line.contains(&format!("XR_RUNTIME_JSON={}", manifest.display())),
            "{line}"
        );
        assert!(line.contains("was found"), "{line}");
        assert!(!line.contains("registered"), "{line}");
    }
}

#[test]
fn a_runtime_manifest_that_is_missing_or_names_no_library_is_named() {
    let Some(_) = monado::monado() else {
        return;
    };
    let dir = temp_dir("xr-fault-manifest");
    let out = dir.join("out");
    let missing = dir.join("nowhere.json");
    let broken = dir.join("broken.json");
    std::fs::write(
        &broken,
        format!(
            r#"{{"file_format_version": "1.0.0", "runtime": {{"name": "broken", "library_path": "{}"}}}}"#,
            dir.join("libnot_a_runtime.so").display()
        ),
    )
    .unwrap();
    for (manifest, expected) in [
        (&missing, "which does not exist"),
        (
            &broken,
            "was found but the OpenXR loader could not load the runtime",
        ),
    ] {
        let o = output(monado::command(manifest, &dir, &xr_args(&out, &[]), NONE));
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        let paragraph = err
            .lines()
            .find(|l| l.starts_with("incise xr needs an OpenXR runtime"))
            .unwrap_or_else(|| panic!("no message in: {err}"));
        assert!(
            paragraph.contains(expected) && paragraph.contains(&manifest.display().to_string()),
            "{paragraph}"
        );
        assert!(!paragraph.contains("registered"), "{paragraph}");
    }
}

#[test]
fn a_runtime_tested_only_with_an_older_vulkan_gets_a_warning_and_the_session_runs() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let dir = temp_dir("xr-fault-vulkan-max");
    let out = dir.join("out");
    let o = output(faulty(
        manifest,
        &dir,
        "vulkan-max:1.1",
        &xr_args(&out, &["--frames", "3"]),
    ));
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let warning = err
        .lines()
        .find(|l| l.starts_with("xr: warning:"))
        .unwrap_or_else(|| panic!("no warning in {err}"));
    assert!(
        warning.contains("tested with Vulkan up to 1.1.0")
            && warning.contains("asks for Vulkan 1.3.0"),
        "{warning}"
    );
    // Without the layer's lower maximum (Monado says 1023.1023.1023) there is none.
    let dir = temp_dir("xr-fault-vulkan-ok");
    let o = output(faulty(
        manifest,
        &dir,
        "",
        &xr_args(&dir.join("out"), &["--frames", "3"]),
    ));
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(!text(&o.stderr).contains("xr: warning:"));
}
