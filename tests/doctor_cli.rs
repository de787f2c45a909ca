//! `incise doctor` (issue 34 item 5) on this machine: with Monado (lavapipe, the null
//! compositor, a simulated headset) every item the headset path needs is ok and it exits
//! 0; with no runtime it names the missing item and the fix and exits 1.
//!
//! The Monado half needs the runtime scripts/monado.sh builds (skipped saying why unless
//! required: `INCISE_REQUIRE_XR=1`, or `CI` set); both halves need a GPU adapter
//! (lavapipe will do).

mod common;

use common::monado::{Validation, command, monado};
use common::{incise_command, temp_dir, text};

#[test]
fn without_a_runtime_doctor_names_what_is_missing_and_fails() {
    let o = incise_command(&["doctor"])
        .env("XR_RUNTIME_JSON", "/nonexistent/openxr_runtime.json")
        .output()
        .unwrap();
    let out = text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}\n{}", text(&o.stderr));
    assert!(out.contains("ok       GPU adapter"), "{out}");
    assert!(out.contains("--device auto:"), "auto's pick and why: {out}");
    assert!(out.contains("ok       Vulkan loader"), "{out}");
    assert!(
        out.contains("missing  runtime manifest XR_RUNTIME_JSON=/nonexistent"),
        "{out}"
    );
    assert!(out.contains("missing  OpenXR headset"), "{out}");
    assert!(out.contains("fix: start an OpenXR runtime"), "{out}");
    assert!(out.contains("the headset path cannot work here"), "{out}");
}

#[test]
fn with_monado_doctor_finds_the_headset_and_passes() {
    let Some(manifest) = monado() else {
        return;
    };
    let scratch = temp_dir("doctor-monado");
    let no_layers = Validation {
        xr: false,
        vulkan: false,
    };
    let o = command(manifest, &scratch, &["doctor"], no_layers)
        .output()
        .unwrap();
    let out = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}\n{}", text(&o.stderr));
    assert!(out.contains("ok       runtime manifest"), "{out}");
    assert!(
        out.lines()
            .any(|l| l.starts_with("ok       OpenXR headset") && l.contains("Monado")),
        "{out}"
    );
    assert!(out.contains("XR_KHR_vulkan_enable2"), "{out}");
    assert!(out.contains("the headset path can work here"), "{out}");
}
