//! End-to-end tests of the mass-spring parts of the `incise` binary: a `MassSpring` scene
//! runs and reports the quantities the model has (never NaN), the haptic-rate loop runs
//! from the CLI and reports what it measured, a bad model field is named with its line,
//! and the loop benchmark prints its JSON.

mod common;

use common::{incise, temp_dir, text};

#[test]
fn shipped_nakao_scene_cuts_and_reports() {
    let out = temp_dir("scene");
    let o = incise(&[
        "run",
        "config/plate_cut_nakao.ron",
        "--frames",
        "60",
        "--vtu-every",
        "30",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // The summary names what the model computes, not a stress it does not.
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("(mass-spring)") && stdout.contains("max displacement"),
        "{stdout}"
    );
    assert!(
        !stdout.contains("NaN") && !stdout.contains("von Mises"),
        "{stdout}"
    );
    let json = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(
        !json.contains("NaN") && !json.contains("von_mises"),
        "{json}"
    );
    let report: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(report["status"], "completed");
    assert_eq!(report["model"], "mass-spring");
    assert_eq!(report["device"], "cpu (mass-spring)");
    let frames = report["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 60);
    for key in [
        "sim_time",
        "substeps",
        "kinetic_energy",
        "volume_ratio",
        "max_displacement",
        "wall_ms",
    ] {
        assert!(frames[0].get(key).is_some(), "frame record lacks {key}");
    }
    for frame in frames {
        for (key, value) in frame.as_object().unwrap() {
            // Figures, and the blade's contact flag.
            assert!(
                value.is_number() || (key == "blade_contact" && value.is_boolean()),
                "frame field {key} is {value}"
            );
        }
    }
    // The tension opens the wound: nodes have moved.
    assert!(frames.last().unwrap()["max_displacement"].as_f64().unwrap() > 1e-4);
    // The blade starts at 0.2 s and runs 0.4 s in these 0.6 s: the mesh has grown.
    assert!(report["mesh"]["nodes"].as_u64().unwrap() > 1_250);
    assert!(report["mesh"]["tets"].as_u64().unwrap() > 3_456);
    assert!(out.join("run.pvd").exists() && out.join("snap_00060.vtu").exists());
}

/// Report frames of the haptic-loop run (10 ms each).
const REPORT_FRAMES: u64 = 120;

#[test]
fn haptic_rate_loop_runs_beside_the_report_loop() {
    let out = temp_dir("haptic");
    // 120 report frames of 10 ms: 1.2 s of wall time with the 1 kHz loop beside them.
    let o = incise(&[
        "run",
        "config/plate_cut_nakao.ron",
        "--haptic-rate",
        "1000",
        "--frames",
        &REPORT_FRAMES.to_string(),
        "--vtu-every",
        "0",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("haptic loop") && !stdout.contains("NaN"),
        "{stdout}"
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["status"], "completed");
    let h = &report["haptic"];
    let loops = h["loops"].as_u64().unwrap();
    let wall = h["wall_s"].as_f64().unwrap();
    let rate = h["achieved_hz"].as_f64().unwrap();
    assert_eq!(h["requested_hz"], 1000.0);
    // A 1 kHz loop, not one tied to the 100 Hz report loop: counted against the report
    // frames of the same run (a loaded machine slows both), at least 3 haptic loops a
    // report frame (6.6–7.9 measured on 2 cores at load average 8–11), where a loop that
    // ran once per report frame makes at most 1.
    let frames = report["frames"].as_array().unwrap();
    assert_eq!(frames.len() as u64, REPORT_FRAMES);
    assert!(
        loops >= 3 * REPORT_FRAMES,
        "the haptic loop ran {loops} times in {REPORT_FRAMES} report frames ({rate:.0} Hz)"
    );
    assert!(
        wall >= 0.01 * REPORT_FRAMES as f64,
        "the report loop ran in real time: {wall} s"
    );
    // The rate reported is the one measured: loops over wall time.
    assert!((rate - loops as f64 / wall).abs() < 1e-6 * rate, "{h}");
    // The loop sleeps to its period, so it cannot run much faster than asked (loose bound:
    // how much slower it runs depends on the machine's load and is not tested).
    assert!(rate <= 1100.0, "{h}");
    // The simulated time is the loops' own: 1 ms each.
    let sim = h["sim_time"].as_f64().unwrap();
    assert!((sim - loops as f64 * 1e-3).abs() < 2e-3, "{h}");
    let force: Vec<f64> = h["last_tool_force"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_f64().unwrap())
        .collect();
    assert!(force.iter().all(|f| f.is_finite()), "{force:?}");
    // Each frame carries the published force and a loop count that never decreases.
    let counts: Vec<u64> = frames
        .iter()
        .map(|f| f["haptic_loops"].as_u64().unwrap())
        .collect();
    assert!(counts.windows(2).all(|w| w[1] >= w[0]) && *counts.last().unwrap() <= loops);
    assert!(
        frames
            .iter()
            .all(|f| f["tool_force"].as_array().unwrap().len() == 3)
    );
    // The tool sits on the plate's top surface at the blade's edge: the virtual spring
    // to the nearest node pulls, so some frame records a non-zero force.
    assert!(h["max_tool_force"].as_f64().unwrap() > 0.0, "{h}");
    // The blade starts at 0.2 s of simulated time; the haptic thread has simulated at
    // least 0.36 s (3 loops of 1 ms in each of 120 frames), so it has cut the plate, on
    // any machine.
    let cuts = h["cut_advances"].as_u64().unwrap();
    let nodes = report["mesh"]["nodes"].as_u64().unwrap();
    eprintln!("haptic: {loops} loops in {wall:.3} s, sim {sim:.3} s, {cuts} cuts, {nodes} nodes");
    assert!(sim >= 0.3, "{h}");
    assert!(cuts > 0 && nodes > 1_250, "{h}, {nodes} nodes");
}

#[test]
fn haptic_rate_needs_a_mass_spring_scene_with_a_stroke() {
    let o = incise(&[
        "run",
        "config/organ_layers.ron",
        "--haptic-rate",
        "1000",
        "--quiet",
        "--out",
        temp_dir("haptic_bad").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("--haptic-rate"),
        "{}",
        text(&o.stderr)
    );
    let o = incise(&["run", "config/plate_cut_nakao.ron", "--haptic-rate", "0"]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("haptic-rate"),
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn bad_model_field_names_file_line_and_field() {
    let dir = temp_dir("bad");
    let scene = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/plate_cut_nakao.ron"),
    )
    .unwrap()
    .replace("tension: Uniform(0.04)", "tension: Uniform(1.5)");
    let path = dir.join("bad.ron");
    std::fs::write(&path, scene).unwrap();
    let o = incise(&[
        "run",
        path.to_str().unwrap(),
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(
        err.contains("bad.ron:") && err.contains("model.tension"),
        "{err}"
    );
}

#[test]
fn loop_benchmark_prints_json() {
    let o = incise(&["experiment", "nakao-bench", "--loops", "20", "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["mesh"][1], 72_000);
    let cases: Vec<&str> = v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["case"].as_str().unwrap())
        .collect();
    assert!(
        cases.contains(&"level 4") && cases.contains(&"full mesh"),
        "{cases:?}"
    );
}

/// Runs `config/chest_incision_nakao.ron` with its localisation replaced by `setting`
/// for 40 frames; returns the report.
fn chest_run(name: &str, setting: &str) -> serde_json::Value {
    let out = temp_dir(name);
    let scene = std::fs::read_to_string("config/chest_incision_nakao.ron")
        .unwrap()
        .replace(
            "localisation: Budget(5.6)",
            &format!("localisation: {setting}"),
        );
    let path = out.join("scene.ron");
    std::fs::write(&path, scene).unwrap();
    let o = incise(&[
        "run",
        path.to_str().unwrap(),
        "--frames",
        "40",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let json = std::fs::read_to_string(out.join("report.json")).unwrap();
    serde_json::from_str(&json).unwrap()
}

/// Issue 21: `incise run` localises a mass-spring scene around the blade; the refresh-rate
/// manager picks the level each frame from the time the last one took, and every frame
/// records the level, the free nodes and the loop split (localise, force, integrate, cut).
#[test]
fn refresh_rate_manager_picks_the_level_each_frame_in_run() {
    let report = chest_run("chest_budget", "Budget(5.6)");
    let frames = report["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 40);
    let mut levels = Vec::new();
    for f in frames {
        for key in ["localise_ms", "force_ms", "integrate_ms", "cut_ms"] {
            let ms = f[key]
                .as_f64()
                .unwrap_or_else(|| panic!("frame lacks {key}: {f}"));
            assert!(ms.is_finite() && ms >= 0.0, "{key} = {ms}");
        }
        levels.push(f["level"].as_u64().expect("a localised frame has a level"));
        assert!(f["free_nodes"].as_u64().unwrap() < 17_582);
    }
    // The manager starts from 64 nodes and grows the set while the force computation
    // takes less than the budget: the level is not a constant.
    assert!(
        levels.iter().min() < levels.iter().max(),
        "the manager kept one level: {levels:?}"
    );
    let l = &report["localisation"];
    assert_eq!(l["mode"], "budget 5.6 ms");
    assert_eq!(l["budget_ms"], 5.6);
    assert_eq!(l["frames"], 40);
    for key in [
        "localise_ms",
        "force_ms",
        "integrate_ms",
        "cut_ms",
        "total_ms",
    ] {
        assert!(l[key]["max"].as_f64().unwrap() >= l[key]["min"].as_f64().unwrap());
    }
    // The blade cut during these frames.
    assert!(l["cut_ms"]["max"].as_f64().unwrap() > 0.0);
}

/// A fixed level keeps it every frame and frees the level-4 neighbourhood of the blade
/// (the paper's chest: 219–232 nodes at level 4; ours, from a coarser wall, 140–220).
#[test]
fn fixed_level_localisation_keeps_its_level() {
    let report = chest_run("chest_level4", "Level(4)");
    for f in report["frames"].as_array().unwrap() {
        assert_eq!(f["level"], 4, "{f}");
        let n = f["free_nodes"].as_u64().unwrap();
        assert!((100..=260).contains(&n), "{n} free nodes at level 4");
    }
    assert!(report["localisation"].get("budget_ms").is_none());
}

/// `incise experiment nakao-chest` prints the paper's chest tables beside ours and writes
/// its files.
#[test]
fn chest_experiment_prints_the_papers_tables_beside_ours() {
    let out = temp_dir("nakao_chest");
    let o = incise(&[
        "experiment",
        "nakao-chest",
        "--loops",
        "20",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let table = text(&o.stdout);
    for row in [
        "| paper (MRI chest wall + heart) | 17582 | 100807 | 19964 | 73279 |",
        "| ours, before the incision | 17582 |",
        "| level 4 | 219–232 |",
        "| level 6 | 346–480 |",
        "| manager, 5.6 ms | 292–471 |",
        "load average",
    ] {
        assert!(table.contains(row), "no {row:?} in\n{table}");
    }
    let csv = std::fs::read_to_string(out.join("loops.csv")).unwrap();
    // A header and 20 loops per case.
    assert_eq!(csv.lines().count(), 1 + 3 * 20, "{csv}");
    assert!(out.join("table.md").exists() && out.join("results.json").exists());
}

/// `incise run --replay-localisation REPORT` on the budgeted chest (its manager choosing
/// each frame's free nodes by wall time) replays the free nodes of the run that wrote
/// REPORT, and with them its every figure, frame by frame; an XPBD scene refuses it.
#[test]
fn a_budgeted_run_replays_with_its_reports_localisation() {
    let run = |out: &std::path::Path, replay: Option<&std::path::Path>| {
        let mut args = vec![
            "run",
            "config/chest_incision_nakao.ron",
            "--frames",
            "20",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ];
        if let Some(r) = replay {
            args.extend(["--replay-localisation", r.to_str().unwrap()]);
        }
        let o = incise(&args);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let json = std::fs::read_to_string(out.join("report.json")).unwrap();
        let report: serde_json::Value = serde_json::from_str(&json).unwrap();
        // The figures the model's state gives, per frame (not its timings).
        let keys = [
            "level",
            "free_nodes",
            "volume_ratio",
            "max_displacement",
            "kinetic_energy",
        ];
        let frames: Vec<Vec<String>> = report["frames"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| keys.iter().map(|k| f[k].to_string()).collect())
            .collect();
        (frames, report["mesh"]["nodes"].clone())
    };
    let dir = temp_dir("replay-localisation");
    let first = run(&dir.join("first"), None);
    assert_eq!(first.0.len(), 20);
    let replay = run(&dir.join("replay"), Some(&dir.join("first/report.json")));
    assert_eq!(replay, first);
    let o = incise(&[
        "run",
        "config/plate_cut.ron",
        "--frames",
        "1",
        "--replay-localisation",
        dir.join("first/report.json").to_str().unwrap(),
        "--out",
        dir.join("xpbd").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("--replay-localisation replays a mass-spring"));
}
