//! Issue 11, fault survival from the command line: a GPU lost mid-run hands over to the
//! CPU with a warning in report.json; a NaN in the solver stops the run with the frame
//! and tet named, the frame rolled back and the output so far kept; Ctrl-C stops a run
//! (exit 130) or an XR session (clean end) with the outputs written.

mod common;

use common::{incise, temp_dir, text};
use incise_sim::gpu::GpuContext;
use incise_test_gate::{Need, or_skip};

fn report(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

#[test]
fn a_lost_gpu_hands_the_run_to_the_cpu() {
    let out = temp_dir("fault-gpu");
    if or_skip(Need::Gpu, GpuContext::new()).is_none() {
        return;
    }
    let o = incise(&[
        "run",
        "config/plate_cut.ron",
        "--device",
        "gpu",
        "--frames",
        "20",
        "--vtu-every",
        "0",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--inject-gpu-loss-at",
        "8",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = report(&out);
    assert_eq!(r["status"], "completed");
    assert_eq!(r["frames"].as_array().unwrap().len(), 20);
    let device = r["device"].as_str().unwrap();
    if device.starts_with("gpu") {
        panic!("the run stayed on the GPU after the loss: {device}");
    }
    assert!(device.contains("after a GPU failure"), "{device}");
    let w = r["warnings"][0].as_str().unwrap();
    assert!(w.contains("frame 8") && w.contains("CPU"), "{w}");
}

#[test]
fn a_nan_stops_the_run_naming_frame_and_tet_and_keeps_the_output() {
    let found = GpuContext::new().map_err(|e| format!("the GPU half: {e}"));
    let gpu = or_skip(Need::Gpu, found).is_some();
    let devices: &[&str] = if gpu { &["cpu", "gpu"] } else { &["cpu"] };
    for &device in devices {
        let out = temp_dir(&format!("fault-nan-{device}"));
        let o = incise(&[
            "run",
            "config/plate_cut.ron",
            "--device",
            device,
            "--frames",
            "20",
            "--vtu-every",
            "5",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--inject-nan-at",
            "12",
        ]);
        assert!(!o.status.success(), "{device}: a NaN must stop the run");
        let err = text(&o.stderr);
        assert!(
            err.contains("frame 12") && err.contains("tet"),
            "{device}: {err}"
        );
        let r = report(&out);
        assert_eq!(r["status"], "failed");
        assert_eq!(
            r["frames"].as_array().unwrap().len(),
            12,
            "{device}: frames before the fault kept"
        );
        assert!(
            out.join("snap_00010.vtu").exists(),
            "{device}: snapshots kept"
        );
    }
}

/// Send SIGINT (Ctrl-C) to `child`.
fn ctrl_c(child: &std::process::Child) {
    let ok = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs")
        .success();
    assert!(ok, "kill -INT failed");
}

/// Ctrl-C stops `incise run` after the frame in hand: exit 130, report.json with status
/// "interrupted" and the frames done, the stroke recorded so far saved in full.
#[test]
fn ctrl_c_stops_a_run_keeping_its_report_and_stroke() {
    let dir = temp_dir("ctrl-c-run");
    let out = dir.join("out");
    let stroke = dir.join("stroke.ron");
    let child = common::incise_command(&[
        "run",
        "config/plate_cut.ron",
        "--device",
        "cpu",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--record-stroke",
        stroke.to_str().unwrap(),
    ])
    .stderr(std::process::Stdio::piped())
    .spawn()
    .expect("incise starts");
    // The first checkpoint (frame 60 of 192) is written: the run is under way.
    let started = std::time::Instant::now();
    while !out.join("report.json").exists() {
        assert!(started.elapsed().as_secs() < 300, "no checkpoint in 5 min");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    ctrl_c(&child);
    let o = child.wait_with_output().unwrap();
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted after"), "{err}");
    let r = report(&out);
    assert_eq!(r["status"], "interrupted", "{r}");
    let frames = r["frames"].as_array().unwrap().len();
    assert!((60..192).contains(&frames), "{frames} frames");
    let s = incise_scalpel::load_stroke(&stroke).unwrap();
    let dt = 1.0 / 60.0;
    assert!(
        (s.end_time() - frames as f64 * dt).abs() < 1.5 * dt,
        "the stroke covers the frames run: {} s for {frames} frames",
        s.end_time()
    );
}

/// Ctrl-C during `incise xr` ends the session through the runtime's shutdown
/// (xrRequestExitSession): exit 130, the report and frame log written; for an XPBD scene
/// and for a Nakao one (its method session, which also writes the body's report.json).
#[test]
fn ctrl_c_ends_an_xr_session_cleanly() {
    for (name, scene) in [
        ("ctrl-c-xr", "config/plate_cut.ron"),
        ("ctrl-c-xr-nakao", "config/plate_cut_nakao.ron"),
    ] {
        let out = xr_interrupted(name, scene);
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("xr_report.json")).unwrap())
                .unwrap();
        assert_eq!(r["exit"], "Interrupted", "{scene}: {r}");
        let frames = r["frames"].as_u64().unwrap();
        assert!(frames < 60 * 72, "{scene} stopped early: {frames} frames");
        assert!(out.join("frames.csv").exists(), "{scene}");
        if scene.ends_with("nakao.ron") {
            assert!(out.join("report.json").exists(), "the body's report");
        }
    }
}

/// `incise xr SCENE` on a 60 s simulated headset, Ctrl-C after 5 s; it must exit 130
/// saying so. Its output folder.
fn xr_interrupted(name: &str, scene: &str) -> std::path::PathBuf {
    let dir = temp_dir(name);
    let script = dir.join("headset.ron");
    // Long enough (60 s of display time) never to finish on its own before the signal.
    std::fs::write(
        &script,
        "(duration: 60.0, eye_size: (64, 64), render_every: 30, \
         head: [(t: 0.0, position: (0.0, 1.25, -0.05), orientation: (-0.34202, 0.0, 0.0, 0.93969))])",
    )
    .unwrap();
    let out = dir.join("out");
    let child = common::incise_command(&[
        "xr",
        scene,
        "--simulated-headset",
        script.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
    .stderr(std::process::Stdio::piped())
    .spawn()
    .expect("incise starts");
    std::thread::sleep(std::time::Duration::from_secs(5));
    ctrl_c(&child);
    let o = child.wait_with_output().unwrap();
    let err = text(&o.stderr);
    // An interrupt says so and uses the interrupted exit code, like `incise run` (issue 19).
    assert_eq!(o.status.code(), Some(130), "{scene}: {err}");
    out
}
