//! End-to-end tests of the `incise` binary: runs, reports, snapshots, errors, mesh tools,
//! benchmark JSON, and the shipped scenes.

mod common;

use common::{incise, temp_dir, text};

use std::path::Path;

/// A small tearing bar: pinned at x = 0, pulled along +x.
const BAR: &str = r#"(
    name: "bar",
    mesh: Generate(Block(min: (0, -0.01, -0.01), size: (0.08, 0.02, 0.02), cells: (16, 4, 4))),
    material: Custom((youngs_modulus: 20e3, poisson_ratio: 0.4, density: 1000)),
    pins: [PlaneSide(point: (0.001, 0, 0), normal: (-1, 0, 0))],
    grabs: [(nodes: PlaneSide(point: (0.079, 0, 0), normal: (1, 0, 0)), path: [(0.06, 0, 0)], speed: 0.1)],
    solver: (substeps: 30, gravity: (0, 0, 0)),
    cutting: Some((von_mises_threshold: 12e3)),
    duration: 0.5,
)"#;

#[test]
fn run_writes_report_snapshots_and_collection() {
    let dir = temp_dir("run");
    let scene = dir.join("bar.ron");
    std::fs::write(&scene, BAR).unwrap();
    let out = dir.join("out");
    let o = incise(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--vtu-every",
        "10",
        "--threads",
        "4",
    ]);
    assert!(o.status.success(), "stderr: {}", text(&o.stderr));
    assert!(text(&o.stdout).contains("report:"));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["status"], "completed");
    // The threads the solver runs on: at most one per core, whatever was asked.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert_eq!(report["threads"], 4.min(cores) as u64);
    let frames = report["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 30, "0.5 s at 60 Hz");
    for key in [
        "sim_time",
        "wall_ms",
        "substeps",
        "max_von_mises",
        "mean_von_mises",
        "released_total",
        "volume_ratio",
        "kinetic_energy",
    ] {
        assert!(frames[0].get(key).is_some(), "frame record lacks {key}");
    }
    let released = frames.last().unwrap()["released_total"].as_u64().unwrap();
    assert!(released > 0, "the bar should tear");
    // The closing line's timing is the report's frame times: the median (nearest rank)
    // and the frames over their summed time.
    let stdout = text(&o.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("completed "))
        .unwrap();
    let mut ms: Vec<f64> = frames
        .iter()
        .map(|f| f["wall_ms"].as_f64().unwrap())
        .collect();
    let sustained = 1e3 * ms.len() as f64 / ms.iter().sum::<f64>();
    ms.sort_by(f64::total_cmp);
    let median = ms[((ms.len() - 1) as f64 * 0.5).round() as usize];
    assert!(
        line.contains(&format!("; {median:.1} ms a frame at the median, "))
            && line.ends_with(&format!(", {sustained:.1} frames a second sustained")),
        "{line}"
    );
    // Releasing is irreversible: the count never decreases.
    let counts: Vec<u64> = frames
        .iter()
        .map(|f| f["released_total"].as_u64().unwrap())
        .collect();
    assert!(counts.windows(2).all(|w| w[1] >= w[0]));
    // Snapshots at frames 0, 10, 20, 30 and a collection naming them.
    let pvd = std::fs::read_to_string(out.join("run.pvd")).unwrap();
    for f in [
        "snap_00000.vtu",
        "snap_00010.vtu",
        "snap_00020.vtu",
        "snap_00030.vtu",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
        assert!(pvd.contains(f), "{f} not in run.pvd");
    }
    let last = std::fs::read_to_string(out.join("snap_00030.vtu")).unwrap();
    for field in ["von_mises", "released", "velocity"] {
        assert!(
            last.contains(&format!("Name=\"{field}\"")),
            "snapshot lacks {field}"
        );
    }
}

#[test]
fn malformed_scene_names_file_line_and_field() {
    let dir = temp_dir("bad-scene");
    let scene = dir.join("bad.ron");
    std::fs::write(
        &scene,
        BAR.replace("duration: 0.5,", "duration: 0.5,\n    durashun: 1,"),
    )
    .unwrap();
    let o = incise(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        dir.join("o").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(err.contains("bad.ron:10:"), "{err}");
    assert!(err.contains("durashun"), "{err}");
}

#[test]
fn unstable_settings_are_refused_with_advice() {
    let dir = temp_dir("unstable");
    let scene = dir.join("stiff.ron");
    // XPBD's substeps: the implicit scheme, which a scene naming none runs, has no such
    // bound.
    std::fs::write(
        &scene,
        BAR.replace("substeps: 30", "scheme: Xpbd, substeps: 2"),
    )
    .unwrap();
    let o = incise(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        dir.join("o").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("stiffness number") && err.contains("use at least"),
        "{err}"
    );
}

#[test]
fn mesh_gen_then_check_round_trips() {
    let dir = temp_dir("gen");
    let base = dir.join("plate");
    let o = incise(&["mesh", "gen", "plate", "--out", base.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(dir.join("plate.obj").exists());
    let o = incise(&[
        "mesh",
        "check",
        dir.join("plate.node").to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let q: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(q["nodes"], 1250);
    assert_eq!(q["tets"], 3456);
    assert_eq!(q["components"], 1);
    assert_eq!(q["degenerate_tets"], 0);
}

#[test]
fn broken_mesh_file_exits_1_naming_file_and_line() {
    let dir = temp_dir("broken");
    let f = dir.join("broken.vtk");
    std::fs::write(
        &f,
        "# vtk DataFile Version 3.0\nbroken\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0\n1 0 0\n0 1 zero\n0 0 1\n",
    )
    .unwrap();
    let o = incise(&["mesh", "check", f.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(err.contains("broken.vtk:8"), "{err}");
}

#[test]
fn degenerate_mesh_is_reported_and_rejected() {
    let dir = temp_dir("degenerate");
    let node = dir.join("flat.node");
    std::fs::write(
        &node,
        "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 0\n",
    )
    .unwrap();
    std::fs::write(dir.join("flat.ele"), "2 4 0\n0 0 1 2 3\n1 0 1 2 4\n").unwrap();
    let o = incise(&["mesh", "check", node.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(out.contains("degenerate tets  1"), "{out}");
    assert!(err.contains("tet 1"), "{err}");
}

#[test]
fn bench_json_has_the_documented_fields() {
    let o = incise(&[
        "bench", "--json", "--case", "plate", "--frames", "1", "--device", "cpu",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let b: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let r = &b["results"][0];
    for key in [
        "case",
        "tets",
        "threads",
        "device",
        "ms_per_substep_median",
        "ms_per_substep_min",
        "peak_mib",
    ] {
        assert!(r.get(key).is_some(), "bench result lacks {key}");
    }
    assert_eq!(r["case"], "plate");
    assert_eq!(
        (r["tets"].as_u64(), r["substeps"].as_u64()),
        (Some(3456), Some(10))
    );
    // Serial first, then all cores (interleaved); a frame is at least its 10 substeps.
    let results = b["results"].as_array().unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert_eq!(results.len(), if cores > 1 { 2 } else { 1 }, "{b}");
    assert_eq!(results[0]["threads"], 1);
    for r in results {
        let f = |k: &str| r[k].as_f64().unwrap();
        assert!(f("ms_per_substep_min") > 0.0, "{r}");
        assert!(f("ms_per_substep_min") <= f("ms_per_substep_median"), "{r}");
        assert!(
            f("ms_per_frame_median") >= 10.0 * f("ms_per_substep_min"),
            "{r}"
        );
    }
}

/// `incise bench --markdown`: the rows of docs/performance.md's table, one per variant,
/// under the line with the command, machine, date and load average.
#[test]
fn bench_markdown_prints_the_documents_rows() {
    let o = incise(&["bench", "--markdown", "--case", "plate", "--frames", "1"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let first = out.lines().next().unwrap();
    assert!(
        first.starts_with("Generated by `incise bench --markdown --case plate --frames 1`")
            && first.contains("logical cores")
            && first.contains(" UTC, load average "),
        "{first}"
    );
    let rows: Vec<Vec<&str>> = out
        .lines()
        .filter(|l| l.starts_with("| plate |"))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    assert!(!rows.is_empty(), "{out}");
    for r in &rows {
        assert_eq!(r[1..4], ["3,456", "1,250", "18"], "{r:?}");
        let (median, min): (f64, f64) = (r[5].parse().unwrap(), r[6].parse().unwrap());
        assert!(0.0 < min && min <= median, "{r:?}");
    }
    assert_eq!(rows[0][4], "1");
}

/// `incise bench realtime` (issue 17, item 6): the scene at its own substeps, one JSON
/// object with the split of a frame; with `--markdown` the CPU kernels and the implicit
/// scheme (issue 31, item 3) interleaved, a
/// row each, under the line with the command, machine, date and load average, the
/// implicit scheme also over the whole scene, each row saying which frames it timed.
#[test]
fn bench_realtime_reports_the_scene_at_its_substeps_with_both_kernels() {
    // plate_cut on XPBD, the scheme whose sweep the JSON's figures describe (the shipped
    // scene names none and runs the implicit scheme; its tool comes from the built-in
    // config/ tree).
    let xpbd = common::scene_on_scheme("plate_cut.ron", "Xpbd", "bench-realtime-xpbd");
    let o = incise(&[
        "bench",
        "realtime",
        "--device",
        "cpu",
        "--json",
        "--scene",
        xpbd.to_str().unwrap(),
        "--frames",
        "3",
    ]);
    let scene = ["--scene", "config/plate_cut.ron", "--frames", "1"];
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r: serde_json::Value = serde_json::from_str(&text(&o.stdout)).unwrap();
    assert_eq!(
        (r["tets"].as_u64(), r["substeps"].as_u64()),
        (Some(24576), Some(24)),
        "{r}"
    );
    assert_eq!(r["cpu_kernel"], "Lanes", "the default kernel: {r}");
    // The frames stepped untimed, which scripts/lane-instructions.sh counts in, and the
    // scene's own (3.2 s at 60 Hz).
    assert_eq!(r["warm_up_frames"].as_u64(), Some(2), "{r}");
    assert_eq!(r["scene_frames"].as_u64(), Some(192), "{r}");
    let f = |k: &str| r[k].as_f64().unwrap();
    assert!(f("substeps_ms_median") > 0.0, "{r}");
    assert!(f("frame_ms_median") >= f("substeps_ms_median"), "{r}");
    assert!(
        (f("frames_per_second") - 1e3 / f("frame_ms_median")).abs() < 1e-6,
        "{r}"
    );
    // What the timed frames sustained: their number over their summed time (the mean of
    // three frames lies within them).
    assert_eq!(r["frames"].as_u64(), Some(3), "{r}");
    assert!(
        (f("frames_per_second_sustained") - 1e3 / f("frame_ms_mean")).abs() < 1e-6
            && f("frame_ms_mean") > 0.0
            && f("frame_ms_mean") <= f("frame_ms_p99") + 1e-9,
        "{r}"
    );
    // What a sweep did: the counted flops of every tet's projection, at the sweep's time.
    let flops = f("flops_per_sweep");
    assert!(flops >= 250.0 * 24576.0, "{r}");
    let gflops = flops / (f("sweep_ms_median") * 1e6);
    assert!((f("gflops") - gflops).abs() <= 1e-9 * gflops, "{r}");
    assert!(
        r["passes_per_frame"].as_u64().unwrap() > 2 * 24,
        "a pass per colour per substep: {r}"
    );
    let o = incise(&[&["bench", "realtime", "--markdown"][..], &scene].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let first = out.lines().next().unwrap();
    assert!(
        first.starts_with("Generated by `incise bench realtime --markdown --scene")
            && first.contains("logical cores")
            && first.contains(" UTC, load average "),
        "{first}"
    );
    let kernels: Vec<&str> = out
        .lines()
        .filter(|l| l.starts_with("| config/plate_cut.ron |"))
        .map(|l| l.split('|').map(str::trim).nth(5).unwrap())
        .collect();
    assert_eq!(
        kernels,
        [
            "Scalar",
            "PortableLanes",
            "Lanes",
            "Lanes, Blocks",
            "Avx2Lanes, Blocks",
            "Newton",
            "Newton, whole scene"
        ],
        "{out}"
    );
    // The unit of the fine-sweeps column: the Lanes row's coloured sweep on all threads.
    let all_sweep = |row: &str| -> f64 {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        cells[8].split_once(" / ").unwrap().1.parse().unwrap()
    };
    let unit = all_sweep(
        out.lines()
            .find(|l| l.starts_with("| config/plate_cut.ron |") && l.contains("| Lanes |"))
            .expect("a Lanes row"),
    );
    // Each kernel's sweep on one thread and on all, and the ratio of the two.
    for row in out
        .lines()
        .filter(|l| l.starts_with("| config/plate_cut.ron |"))
    {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        // The frame in fine sweeps: its median ms over the Lanes sweep, as printed (to
        // the rounding of the printed figures); the implicit scheme's too.
        let sweeps: f64 = cells[15].parse().unwrap();
        let frame: f64 = cells[6].split_once(" / ").unwrap().1.parse().unwrap();
        let want = frame / unit;
        assert!(
            (sweeps - want).abs() <= 0.1 + 0.03 * want,
            "fine sweeps a frame {sweeps} against {frame} / {unit} ms: {row}"
        );
        // The frames timed after the two warm-up ones: `--frames 1`, or all the scene's.
        let whole = cells[5].ends_with(", whole scene");
        assert_eq!(cells[16], if whole { "2–191" } else { "2–2" }, "{row}");
        // Each run's 95th-percentile frame is at least its median frame.
        let p95: f64 = cells[17].parse().unwrap();
        assert!(
            p95 >= frame - 0.05,
            "p95 {p95} against the median {frame}: {row}"
        );
        // The frames a second each run sustained (its frames over their summed time): with
        // one frame timed, the median frame's rate.
        let sustained: f64 = cells[18].parse().unwrap();
        let fps: f64 = cells[7].parse().unwrap();
        assert!(sustained > 0.0, "{row}");
        if !whole {
            assert!(
                (sustained - fps).abs() <= 0.15,
                "{sustained} against {fps}: {row}"
            );
        }
        if cells[5].starts_with("Newton") {
            // No sweeps to time or count flops of.
            assert_eq!(
                (cells[8], cells[10], cells[11]),
                ("– / –", "–", "–"),
                "{row}"
            );
            continue;
        }
        let (one, all) = cells[8].split_once(" / ").unwrap();
        let (one, all): (f64, f64) = (one.parse().unwrap(), all.parse().unwrap());
        let scaling: f64 = cells[9].trim_end_matches('×').parse().unwrap();
        assert!(one > 0.0 && all > 0.0, "{row}");
        assert!((scaling - one / all).abs() < 0.01 + 0.01 * scaling, "{row}");
        assert!(cells[10].parse::<f64>().unwrap() > 0.0, "GFLOP/s: {row}");
    }
    // The headset table (issue 31, item 3): the scene on its own scheme, then on the
    // other, in a simulated headset on the wall clock, where a renderer for its eyes exists.
    let rows: Vec<Vec<&str>> = out
        .lines()
        .skip_while(|l| !l.starts_with("Headset: "))
        .filter(|l| l.starts_with("| XPBD") || l.starts_with("| Newton"))
        .map(|l| l.split('|').map(str::trim).collect())
        .collect();
    if incise_xr::RenderDevice::headless().is_ok() {
        // plate_cut names no scheme: its own is the implicit one, then XPBD at its
        // substeps; each with the eyes drawn and with them left to a GPU.
        let names: Vec<(&str, &str)> = rows.iter().map(|r| (r[1], r[2])).collect();
        assert_eq!(
            names,
            [
                ("Newton", "drawn"),
                ("Newton", "not drawn"),
                ("XPBD, 24 substeps", "drawn"),
                ("XPBD, 24 substeps", "not drawn")
            ],
            "{out}"
        );
        // Its controllers are untracked: the caption says the scalpel stays out.
        let caption = out.lines().find(|l| l.starts_with("Headset: ")).unwrap();
        assert!(
            caption.contains("the scene's scalpel never reaches the tissue"),
            "{caption}"
        );
        let low = |cell: &str| -> f64 { cell.split_once('–').unwrap().0.parse().unwrap() };
        for r in &rows {
            assert!(low(r[3]) > 0.0, "simulation frames a second: {out}");
            assert!(low(r[4]) > 0.0 && low(r[5]) >= low(r[4]), "latency: {out}");
            assert!((0.0..=100.0).contains(&low(r[6])), "within: {out}");
        }
    } else {
        assert!(out.contains("Headset: not measured: "), "{out}");
    }
    assert!(
        out.contains("Flops of a sweep: ") && out.contains(" per tet projection"),
        "{out}"
    );
}

/// Every shipped scene parses, resolves its material and builds a stable solver.
#[test]
fn shipped_scenes_build() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["intestine_pull", "plate_stretch", "beam_sag"] {
        let path = root.join("config").join(format!("{name}.ron"));
        let scene = incise::scene::load_scene(&path).unwrap();
        let built = incise::scene::build_scene(&scene, &path, Some(1))
            .unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert!(built.pinned_nodes > 0, "{name} pins nothing");
    }
}

/// Every shipped scene (each `config/*.ron` but the preset files) runs three frames from
/// the command line and completes with its mesh and frames in report.json; the folder
/// holds the twelve scenes the README lists.
#[test]
fn every_shipped_scene_runs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    let dir = temp_dir("shipped");
    let mut scenes: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .filter(|p| {
            !["materials.ron", "rheology.ron"].contains(&p.file_name().unwrap().to_str().unwrap())
        })
        .collect();
    scenes.sort();
    assert_eq!(scenes.len(), 12, "{scenes:?}");
    for scene in &scenes {
        let name = scene.file_stem().unwrap().to_str().unwrap();
        let out = dir.join(name);
        let o = run_three_frames(scene, &out);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let r: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        assert_eq!(r["status"], "completed", "{name}");
        assert_eq!(r["frames"].as_array().unwrap().len(), 3, "{name}");
        assert!(r["mesh"]["tets"].as_u64().unwrap() > 0, "{name}");
    }
}

/// A scene on the implicit scheme (`solver.scheme: Newton`, issue 31) runs on either
/// device: `--device auto` picks one by the adapter, as for XPBD, and says why, and
/// `--device gpu` runs it on the GPU (issue 31, item 4); its settings are checked like the
/// others', naming the field, and a misspelt one names the scene's line.
#[test]
fn the_implicit_scheme_runs_on_either_device_and_checks_its_settings() {
    let dir = temp_dir("newton");
    let run = |scene: &str, device: &str, out: &str| {
        incise(&[
            "run",
            scene,
            "--frames",
            "1",
            "--vtu-every",
            "0",
            "--device",
            device,
            "--out",
            dir.join(out).to_str().unwrap(),
        ])
    };
    let o = run("config/intestine_pull.ron", "auto", "auto");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("auto/report.json")).unwrap()).unwrap();
    let choice = r["device_choice"].as_str().unwrap();
    assert!(choice.starts_with("--device auto: "), "{r}");
    if incise_xr::RenderDevice::headless().is_ok() {
        let o = run("config/intestine_pull.ron", "gpu", "gpu");
        assert!(o.status.success(), "{}", text(&o.stderr));
        let r: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("gpu/report.json")).unwrap()).unwrap();
        assert!(r["device"].as_str().unwrap().starts_with("gpu"), "{r}");
        assert_eq!(r["frames"].as_array().unwrap().len(), 1, "{r}");
    }
    let original = std::fs::read_to_string("config/bowel_cantilever.ron").unwrap();
    assert!(original.contains("scheme: Newton(()),"));
    let write = |name: &str, scheme: &str| {
        let path = dir.join(name);
        std::fs::write(&path, original.replace("scheme: Newton(()),", scheme)).unwrap();
        std::fs::copy("config/materials.ron", dir.join("materials.ron")).unwrap();
        path
    };
    let zero = write("zero_steps.ron", "scheme: Newton((steps: 0)),");
    let o = run(zero.to_str().unwrap(), "cpu", "zero");
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("solver.scheme.steps must be 1..=1000, got 0"),
        "{}",
        text(&o.stderr)
    );
    let typo = write("typo.ron", "scheme: Newton((stepz: 2)),");
    let o = run(typo.to_str().unwrap(), "cpu", "typo");
    assert!(!o.status.success());
    let line = original
        .lines()
        .position(|l| l.contains("scheme: Newton"))
        .unwrap()
        + 1;
    assert!(
        text(&o.stderr).contains(&format!("typo.ron:{line}:")) && text(&o.stderr).contains("stepz"),
        "{}",
        text(&o.stderr)
    );
    // The Gauss–Seidel smoother exists on the CPU only: auto picks the CPU and says why,
    // the GPU refuses it by name.
    let smoothed = write(
        "gauss_seidel.ron",
        "scheme: Newton((smoother: GaussSeidel)),",
    );
    let o = run(smoothed.to_str().unwrap(), "auto", "gs_auto");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("gs_auto/report.json")).unwrap()).unwrap();
    assert!(r["device"].as_str().unwrap().starts_with("cpu"), "{r}");
    assert!(
        r["device_choice"].as_str().unwrap().contains("GaussSeidel"),
        "{r}"
    );
    if incise_xr::RenderDevice::headless().is_ok() {
        let o = run(smoothed.to_str().unwrap(), "gpu", "gs_gpu");
        assert!(!o.status.success());
        assert!(
            text(&o.stderr).contains("smoother GaussSeidel runs on the CPU only"),
            "{}",
            text(&o.stderr)
        );
    }
}

/// `--device auto` says in report.json what it picked and why: on a software adapter
/// (lavapipe, as in CI) the CPU solver, which is faster there; on a hardware GPU the GPU;
/// without an adapter the CPU.
#[test]
fn device_auto_picks_the_faster_path_and_says_why() {
    let dir = temp_dir("auto");
    let o = incise(&[
        "run",
        "config/beam_sag.ron",
        "--frames",
        "2",
        "--vtu-every",
        "0",
        "--device",
        "auto",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    let (device, why) = (
        r["device"].as_str().unwrap(),
        r["device_choice"].as_str().unwrap(),
    );
    assert!(text(&o.stderr).contains(why), "the choice is also printed");
    match incise_xr::RenderDevice::headless() {
        Ok(dev) if dev.info.device_type == wgpu::DeviceType::Cpu => {
            assert_eq!(device, "cpu", "{why}");
            assert!(
                why.contains("software") && why.contains(&dev.info.name),
                "{why}"
            );
        }
        Ok(dev) => {
            assert!(device.starts_with("gpu"), "{device}: {why}");
            assert!(
                why.contains("hardware") && why.contains(&dev.info.name),
                "{why}"
            );
        }
        Err(e) => {
            let skipped = format!("{e}: only the fallback to the CPU is checked");
            incise_test_gate::skip_or_fail(incise_test_gate::Need::Gpu, skipped);
            assert_eq!(device, "cpu");
            assert!(why.contains("no GPU adapter"), "{why}");
        }
    }
}

/// The default scene tears: run its first 90 frames (1.5 s) and expect released tets and
/// a wall that comes apart into more than one piece.
#[test]
fn intestine_pull_tears() {
    let dir = temp_dir("intestine");
    let o = incise(&[
        "run",
        "config/intestine_pull.ron",
        "--frames",
        "90",
        "--vtu-every",
        "0",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    let last = report["frames"].as_array().unwrap().last().unwrap().clone();
    assert!(last["released_total"].as_u64().unwrap() > 100, "{last}");
    assert_eq!(report["mesh"]["tets"], 34176);
}

/// `--device gpu` runs the same scene on the adapter and reports it; the result agrees
/// with `--device cpu` (same released count). Skipped without an adapter unless the GPU
/// is required (crates/test-gate).
#[test]
fn device_gpu_matches_device_cpu() {
    let gate = incise_test_gate::Need::Gpu;
    if incise_test_gate::or_skip(gate, incise_sim::gpu::GpuContext::new()).is_none() {
        return;
    }
    let dir = temp_dir("device");
    let scene = dir.join("bar.ron");
    std::fs::write(&scene, BAR).unwrap();
    let mut released = Vec::new();
    for device in ["cpu", "gpu"] {
        let out = dir.join(device);
        let o = incise(&[
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--device",
            device,
            "--vtu-every",
            "0",
            "--quiet",
        ]);
        assert!(o.status.success(), "{device}: {}", text(&o.stderr));
        let r: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        let d = r["device"].as_str().unwrap().to_string();
        assert!(d.starts_with(device), "{d}");
        released.push(
            r["frames"].as_array().unwrap().last().unwrap()["released_total"]
                .as_u64()
                .unwrap(),
        );
    }
    assert_eq!(released[0], released[1]);
    assert!(released[0] > 0);
}

/// `incise compare` runs the tearing bar on both devices, on its default (implicit) scheme
/// and on XPBD, and finds them in agreement: positions within 10⁻⁴ of the mesh up to the
/// tear, the same tets released. On the implicit scheme the torn pieces then drift apart
/// by millimetres (the inexact solve carries the devices' rounding; a thousand times
/// tighter, 50 µm), which compare reports and does not judge.
#[test]
fn compare_finds_cpu_and_gpu_in_agreement() {
    let gate = incise_test_gate::Need::Gpu;
    if incise_test_gate::or_skip(gate, incise_sim::gpu::GpuContext::new()).is_none() {
        return;
    }
    let dir = temp_dir("compare");
    for (name, text_) in [
        ("bar.ron", BAR.to_string()),
        (
            "bar_xpbd.ron",
            BAR.replace("substeps: 30", "scheme: Xpbd, substeps: 30"),
        ),
    ] {
        let scene = dir.join(name);
        std::fs::write(&scene, text_).unwrap();
        // Without --frames: the scene's duration, 0.5 s at 60 Hz.
        let o = incise(&["compare", scene.to_str().unwrap(), "--json"]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let c: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(c["frames"], 30, "{name}: {c}");
        assert_eq!(c["agree"], true, "{name}: {c}");
        assert!(c["released_cpu"].as_u64().unwrap() > 0, "{name}: {c}");
        assert_eq!(c["released_mismatch"], 0, "{name}: {c}");
        let tear = c["tear_frame"].as_u64().expect("the bar tears");
        assert!((20..29).contains(&tear), "{name}: {c}");
        let f = |k: &str| c[k].as_f64().unwrap();
        assert!(
            f("max_position_difference") <= 1e-4 * f("mesh_size"),
            "{name}: {c}"
        );
        if name == "bar.ron" {
            // The torn pieces' drift is there to see, beyond what is judged before the tear.
            assert!(
                f("max_position_difference_after_tear") > 1e-4 * f("mesh_size"),
                "{name}: {c}"
            );
        }
    }
}

/// Run `scene` for three frames on the CPU into `out`.
fn run_three_frames(scene: &Path, out: &Path) -> std::process::Output {
    incise(&[
        "run",
        scene.to_str().unwrap(),
        "--frames",
        "3",
        "--vtu-every",
        "0",
        "--device",
        "cpu",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ])
}

/// A shipped scene copied into a folder of its own runs (issue 34, item 2): its material or
/// rheology presets, and its scalpel's tool file, come from the built-in copies of
/// config/'s files when none lies beside it, and the report says which preset file was
/// read; a file beside the scene wins. A preset file that is neither there nor shipped is an error that names it and
/// the OS's cause once.
#[test]
fn a_scene_copied_anywhere_runs_with_the_built_in_presets() {
    let dir = temp_dir("scene-anywhere");
    for name in ["plate_stretch.ron", "organ_layers.ron", "plate_cut.ron"] {
        let scene = dir.join(name);
        std::fs::copy(Path::new("config").join(name), &scene).unwrap();
        let o = run_three_frames(&scene, &dir.join(format!("out-{name}")));
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        assert!(
            !text(&o.stderr).contains("error"),
            "{name}: {}",
            text(&o.stderr)
        );
    }
    let r: serde_json::Value = serde_json::from_slice(
        &std::fs::read(dir.join("out-organ_layers.ron/report.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        r["rheology"]["presets_file"], "built-in config/rheology.ron",
        "{r}"
    );
    // A preset file beside the scene wins: an unusable one is refused, naming it.
    std::fs::write(
        dir.join("materials.ron"),
        "{ \"skin\": (youngs_modulus: -1.0, poisson_ratio: 0.45, density: 1000.0) }",
    )
    .unwrap();
    let o = run_three_frames(&dir.join("plate_stretch.ron"), &dir.join("out-local"));
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains(&format!("{}", dir.join("materials.ron").display())),
        "{}",
        text(&o.stderr)
    );
    // Neither beside the scene nor shipped: named once, with its cause once.
    let own = std::fs::read_to_string("config/organ_layers.ron")
        .unwrap()
        .replace("presets: \"rheology.ron\"", "presets: \"mine.ron\"");
    std::fs::write(dir.join("mine_layers.ron"), own).unwrap();
    let o = run_three_frames(&dir.join("mine_layers.ron"), &dir.join("out-mine"));
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert_eq!(err.matches("mine.ron").count(), 1, "{err}");
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}
