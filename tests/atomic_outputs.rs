//! Issue 11: outputs are atomic. `incise run` is killed with SIGKILL at pseudo-random
//! moments, 40 times (10 more runs finish); afterwards every output file is either absent
//! or complete and parseable (report.json, every .vtu snapshot, every PNG screenshot,
//! run.pvd, the recorded stroke). Leftover `.tmp` siblings are allowed: they are never read and the next write
//! replaces them. Report and stroke are checkpointed every second of simulated time, so a
//! killed run keeps them up to its last checkpoint.

mod common;

use std::time::Duration;

use common::{incise_command, temp_dir};

/// The same deterministic sequence on every run (so a failure can be replayed), spread
/// over 0.02–1.2 × `full`, the time of one uninterrupted run.
fn delays(n: usize, full: Duration) -> Vec<Duration> {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            full.mul_f64(0.02 + 1.18 * (x % 10_000) as f64 / 10_000.0)
        })
        .collect()
}

#[test]
fn a_run_killed_at_any_moment_leaves_only_complete_files() {
    let base = temp_dir("atomic-kill");
    let (mut vtus, mut reports, mut strokes, mut pngs) = (0, 0, 0, 0);
    let args = |out: &std::path::Path, stroke: &std::path::Path| {
        [
            "run",
            "config/plate_cut.ron",
            "--device",
            "cpu",
            "--frames",
            "12",
            "--vtu-every",
            "1",
            "--screenshot-every",
            "2",
            "--screenshot-size",
            "160x120",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--record-stroke",
            stroke.to_str().unwrap(),
        ]
        .map(String::from)
    };
    let t = std::time::Instant::now();
    let full_out = base.join("full");
    let status = incise_command(&[])
        .args(args(&full_out, &full_out.join("stroke.ron")))
        .status()
        .expect("incise runs");
    assert!(status.success());
    let full = t.elapsed();
    for (k, delay) in delays(50, full).into_iter().enumerate() {
        let out = base.join(format!("run{k}"));
        let stroke = out.join("stroke.ron");
        let mut child = incise_command(&[])
            .args(args(&out, &stroke))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("incise starts");
        // Every fifth run is left to finish, so complete reports are checked too
        // whatever the machine's load; the others are killed.
        if k % 5 == 4 {
            let _ = child.wait();
        } else {
            std::thread::sleep(delay);
            let _ = child.kill();
            let _ = child.wait();
        }
        let Ok(entries) = std::fs::read_dir(&out) else {
            continue;
        };
        for e in entries {
            let path = e.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if name.ends_with(".tmp") {
                continue;
            }
            if name.ends_with(".png") {
                pngs += 1;
                let ok = incise_xr::RgbaImage::load_png(&path).is_ok();
                assert!(ok, "kill {k} after {delay:?}: {name} is incomplete");
                continue;
            }
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("kill {k} after {delay:?}: {name} unreadable: {e}"));
            let ok = if name.ends_with(".vtu") {
                vtus += 1;
                incise_sim::io::parse_vtu(&text, &path).is_ok()
            } else if name == "report.json" {
                reports += 1;
                serde_json::from_str::<serde_json::Value>(&text).is_ok()
            } else if name == "stroke.ron" {
                strokes += 1;
                incise_scalpel::parse_stroke(&text, &path).is_ok()
            } else if name == "run.pvd" {
                text.trim_end().ends_with("</VTKFile>")
            } else {
                panic!("unexpected output {name}");
            };
            assert!(ok, "kill {k} after {delay:?}: {name} is incomplete");
        }
    }
    println!(
        "checked {vtus} snapshots, {pngs} screenshots, {reports} reports, {strokes} strokes after 40 kills and 10 whole runs"
    );
    assert!(pngs > 20, "too few screenshots written to test ({pngs})");
    assert!(
        vtus > 50,
        "the kills came too early to test anything ({vtus} snapshots)"
    );
    assert!(
        reports > 0,
        "no run finished before its kill, so report.json was not tested"
    );
}

/// A long run killed after its first checkpoint keeps a parseable report (status
/// "running", every frame up to the checkpoint) and the stroke recorded so far.
#[test]
fn a_killed_run_keeps_its_checkpointed_report_and_stroke() {
    let out = temp_dir("atomic-checkpoint");
    let stroke = out.join("stroke.ron");
    let mut child = incise_command(&[
        "run",
        "config/plate_cut.ron",
        "--device",
        "cpu",
        "--frames",
        "100000",
        "--vtu-every",
        "0",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--record-stroke",
        stroke.to_str().unwrap(),
    ])
    .stdout(std::process::Stdio::null())
    .stderr(std::process::Stdio::null())
    .spawn()
    .expect("incise starts");
    let report = out.join("report.json");
    let t = std::time::Instant::now();
    while !(report.exists() && stroke.exists()) && t.elapsed() < Duration::from_secs(300) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("a checkpoint")).unwrap();
    assert_eq!(r["status"], "running");
    assert!(r["frames"].as_array().unwrap().len() >= 60);
    let s = incise_scalpel::load_stroke(&stroke).expect("the stroke so far parses");
    assert!(s.keys().len() >= 61, "{} keys", s.keys().len());
}
