//! Issue 11, soak: CI's 5-minute variant of the 1-hour endurance run (`incise soak`):
//! the incision scene is cut, reset and cut again for 2.5 minutes on the CPU and 2.5 on
//! the GPU (lavapipe in CI); memory stays within 5 % after the warm-up cut, no file
//! descriptor leaks, every cut releases exactly the first cut's tets.
//! `INCISE_SOAK_SECONDS` changes the duration per device.

mod common;

use common::{gpu_required, incise, temp_dir, text};

fn soak(device: &str) {
    let seconds = std::env::var("INCISE_SOAK_SECONDS").unwrap_or_else(|_| "150".into());
    let out = temp_dir(&format!("soak-{device}"));
    let o = incise(&[
        "soak",
        "config/plate_cut.ron",
        "--seconds",
        &seconds,
        "--device",
        device,
        "--out",
        out.to_str().unwrap(),
    ]);
    let report = std::fs::read_to_string(out.join("soak.json")).unwrap_or_default();
    println!("{}", text(&o.stdout));
    assert!(o.status.success(), "{}\n{report}", text(&o.stderr));
    let r: serde_json::Value = serde_json::from_str(&report).expect("soak.json");
    assert!(r["cycles"].as_array().unwrap().len() >= 3);
    assert_eq!(r["passed"], true);
}

#[test]
fn soak_on_the_cpu() {
    soak("cpu");
}

#[test]
fn soak_on_the_gpu() {
    if incise_sim::gpu::GpuContext::new().is_err() && !gpu_required() {
        eprintln!("skipping the GPU soak: no adapter");
        return;
    }
    soak("gpu");
}
