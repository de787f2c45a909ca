//! Issue 11, fault survival from the command line: a GPU lost mid-run hands over to the
//! CPU with a warning in report.json; a NaN in the solver stops the run with the frame
//! and tet named, the frame rolled back and the output so far kept.

mod common;

use common::{incise, temp_dir, text};

fn report(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

#[test]
fn a_lost_gpu_hands_the_run_to_the_cpu() {
    let out = temp_dir("fault-gpu");
    let o = incise(&[
        "run",
        "config/plate_cut.ron",
        "--device",
        "auto",
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
    if device.contains("after a GPU failure") {
        let w = r["warnings"][0].as_str().unwrap();
        assert!(w.contains("frame 8") && w.contains("CPU"), "{w}");
    } else {
        // No adapter at all: --device auto ran on the CPU from the start.
        assert!(
            std::env::var("INCISE_REQUIRE_GPU").is_err(),
            "no GPU under INCISE_REQUIRE_GPU=1"
        );
    }
}

#[test]
fn a_nan_stops_the_run_naming_frame_and_tet_and_keeps_the_output() {
    for device in ["cpu", "auto"] {
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
