//! `incise xr` against a real OpenXR runtime (issue 19): Monado, built by
//! scripts/monado.sh, headless (null compositor, simulated HMD and controllers), with the
//! OpenXR core and Vulkan validation layers on. The session runs through every state to
//! EXITING, renders into Monado's swapchains and writes its report and stroke; a recorded
//! stroke played with `--stroke` cuts the slab along its path through the real runtime,
//! vibrating only while the blade is in the tissue, and its recording replays headless
//! with `incise run` to the same cut. Under CI a Monado that cannot be built fails.

mod common;

use common::monado::{self, assert_validation_clean};
use common::xr_report::{assert_slow_sim_steps_less_and_lags, num};
use common::{incise, temp_dir, text};
use serde_json::Value;

const SCENE: &str = "config/plate_cut.ron";

/// The report's session states.
fn states(r: &Value) -> Vec<String> {
    r["session_states"]
        .as_array()
        .unwrap_or_else(|| panic!("no session_states: {r}"))
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn a_session_on_monado_runs_from_idle_to_exiting_and_renders_every_frame_it_may() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let layers = monado::validation();
    let dir = temp_dir("xr-monado-session");
    let out = dir.join("out");
    let o = monado::run(
        manifest,
        &dir,
        &[
            "xr",
            SCENE,
            "--frames",
            "30",
            "--device",
            "cpu",
            "--out",
            out.to_str().unwrap(),
        ],
        layers,
    );
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        text(&o.stdout).contains("exit Exited"),
        "{}",
        text(&o.stdout)
    );
    let r = monado::report(&out, &o);
    assert!(
        r["headset"].as_str().unwrap().starts_with("Monado"),
        "{}",
        r["headset"]
    );
    assert_eq!(r["exit"], "Exited");
    // The whole lifecycle, as the OpenXR specification orders it.
    assert_eq!(
        states(&r),
        [
            "Idle",
            "Ready",
            "Synchronized",
            "Visible",
            "Focused",
            "Visible",
            "Synchronized",
            "Stopping",
            "Idle",
            "Exiting"
        ]
    );
    assert_eq!(r["frames"].as_u64(), Some(30), "{r}");
    // Every frame but the first (begun while SYNCHRONIZED) is rendered and submitted.
    let rendered = r["rendered"].as_u64().unwrap();
    assert!(rendered >= 28, "{rendered} of 30 frames rendered: {r}");
    assert!(r["sim_frames"].as_u64().unwrap() > 0, "{r}");
    // Monado's simulated controllers are tracked but never pressed: no cut, no vibration.
    assert_eq!(r["released_tets"].as_u64(), Some(0), "{r}");
    assert_eq!(r["haptic_pulses"].as_u64(), Some(0), "{r}");
    assert_eq!(r["haptic_stops"].as_u64(), Some(0), "{r}");
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!(csv.lines().count(), 31);
    // Display frames the runtime skipped while incise was late, counted from the
    // predicted display times at its nominal period: the shortest it predicted after the
    // first rendered frame (before it, Monado guesses 16 ms; then its null compositor's
    // 50 ms, stretched for a slow app).
    assert_eq!(r["sim_mode"], "thread", "the default: {r}");
    assert!(r["display_hz"].as_f64().unwrap() > 1.0, "{r}");
    let rows: Vec<(f64, f64, bool)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[1].parse().unwrap(), c[11].parse().unwrap(), c[7] == "1")
        })
        .collect();
    let first = rows.iter().position(|r| r.2).unwrap();
    let nominal = rows[first + 1..]
        .iter()
        .map(|r| r.1)
        .fold(f64::INFINITY, f64::min);
    assert!(
        (r["display_hz"].as_f64().unwrap() - 1.0 / nominal).abs() < 1e-3,
        "{r}"
    );
    let skipped: u64 = rows
        .windows(2)
        .map(|w| (((w[1].0 - w[0].0) / nominal).round() as u64).saturating_sub(1))
        .sum();
    // (The CSV's microsecond times can round a gap across a half period.)
    let dropped = r["dropped_frames"].as_u64().unwrap();
    assert!(
        dropped.abs_diff(skipped) <= 1 + skipped / 50,
        "{dropped} dropped, {skipped} from frames.csv: {r}"
    );
    assert!(r["sim_steps_per_s"].as_f64().unwrap() > 0.0, "{r}");
    // The fixed grip pose was recorded, and loads as a stroke.
    let stroke = incise_scalpel::load_stroke(&out.join("stroke.ron")).unwrap();
    assert!(stroke.keys().len() > 1);
    assert_validation_clean(&o, &dir, layers);
}

/// The tet count in `incise run`'s summary line ("… N tets released …").
fn released_in_summary(summary: &str) -> f64 {
    let words: Vec<&str> = summary.split_whitespace().collect();
    words
        .windows(2)
        .find(|w| w[1] == "tets")
        .and_then(|w| w[0].parse().ok())
        .unwrap_or_else(|| panic!("no tet count in {summary}"))
}

/// Frames of the log's `haptic` column where the vibration went from on to off.
fn haptic_endings(csv: &str) -> u64 {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "haptic").unwrap();
    let mut on = false;
    let mut endings = 0;
    for l in lines {
        let now = l.split(',').nth(col).unwrap().parse::<f64>().unwrap() > 0.0;
        if on && !now {
            endings += 1;
        }
        on = now;
    }
    endings + u64::from(on)
}

#[test]
fn a_stroke_played_through_monado_cuts_along_it_and_replays_to_the_same_cut() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let layers = monado::validation();
    let dir = temp_dir("xr-monado-stroke");
    // The scene's own incision (x 1.5 → 5.5 cm at y = 2 cm, 5 mm deep), its first 1.5 s
    // recorded headless.
    let stroke = dir.join("incision.ron");
    let o = incise(&[
        "run",
        SCENE,
        "--frames",
        "90",
        "--record-stroke",
        stroke.to_str().unwrap(),
        "--out",
        dir.join("recorded").to_str().unwrap(),
        "--vtu-every",
        "0",
        "--device",
        "cpu",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));

    let out = dir.join("out");
    let session = monado::run(
        manifest,
        &dir,
        &[
            "xr",
            SCENE,
            "--stroke",
            stroke.to_str().unwrap(),
            "--device",
            "cpu",
            "--out",
            out.to_str().unwrap(),
        ],
        layers,
    );
    let err = text(&session.stderr);
    assert_eq!(session.status.code(), Some(0), "{err}");
    let r = monado::report(&out, &session);
    assert_eq!(r["exit"], "Exited", "{r}");
    assert!(states(&r).contains(&"Focused".to_string()), "{r}");
    // The session ended when the stroke had been played: 1.5 s of 1/60 s frames.
    let sim = r["sim_frames"].as_u64().unwrap();
    assert!((90..=92).contains(&sim), "{sim} simulation frames: {r}");
    let live = r["released_tets"].as_f64().unwrap();
    assert!(live > 20.0, "the stroke cut through the runtime: {r}");
    assert!(r["max_tool_force"].as_f64().unwrap() > 0.05, "{r}");
    // Along the stroke: the blade entered at x = 1.5 cm and had reached about 4 cm,
    // on the line y = 2 cm, from the top (z = 2 cm) down.
    let b = &r["cut_box"];
    let (lo, hi) = (&b[0], &b[1]);
    let f = |v: &Value, i: usize| v[i].as_f64().unwrap();
    assert!(f(lo, 0) > 0.010 && f(hi, 0) < 0.045, "x: {b}");
    assert!(f(hi, 0) - f(lo, 0) > 0.010, "the cut runs along x: {b}");
    assert!(f(lo, 1) > 0.014 && f(hi, 1) < 0.026, "y: {b}");
    assert!(f(hi, 2) < 0.021 && f(lo, 2) > 0.010, "z: {b}");

    // Vibration while the blade is in the tissue, one stop each time it left (and none on
    // the frames it was out).
    let pulses = r["haptic_pulses"].as_u64().unwrap();
    let stops = r["haptic_stops"].as_u64().unwrap();
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert!(pulses > 0, "{r}");
    assert!(stops >= 1, "{r}");
    assert_eq!(stops, haptic_endings(&csv), "one stop per contact: {r}");
    assert!(
        stops < r["frames"].as_u64().unwrap() / 4,
        "stops only when the blade leaves: {r}"
    );

    // The session's recording replays headless to the same cut (within 5 %).
    let o = incise(&[
        "run",
        SCENE,
        "--stroke",
        out.join("stroke.ron").to_str().unwrap(),
        "--frames",
        &sim.to_string(),
        "--out",
        dir.join("replay").to_str().unwrap(),
        "--vtu-every",
        "0",
        "--device",
        "cpu",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let replayed = released_in_summary(&text(&o.stdout));
    assert!(
        (replayed - live).abs() <= 0.05 * live,
        "replay {replayed} vs session {live} tets"
    );
    assert_validation_clean(&session, &dir, layers);
}

/// Display refreshes missed after the first five frames (the start-up: the renderer's
/// first pipeline compiles beside the solver's first steps, up to 0.6 s under the
/// validation layers), counted from `out`/frames.csv at the report's display rate.
fn steady_dropped(out: &std::path::Path, r: &Value) -> f64 {
    let period = 1.0 / num(r, "display_hz");
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    let times: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    times[5..]
        .windows(2)
        .map(|w| (((w[1] - w[0]) / period).round() - 1.0).max(0.0))
        .sum()
}

/// Issue 19 item 3 on a real runtime: with the solver on its own thread (the default),
/// a solver slowed by 250 ms a frame costs Monado's display no frame: its own work per
/// frame stays far under the slow step, Monado keeps its 20 Hz and the display shows
/// several frames per simulation step, while the simulation's steps per second fall
/// below 4. The same slowness stepped inside the frame loop (`--sim in-frame`) makes
/// every frame wait for it and drops more refreshes than it shows. Each run is judged
/// against the slowness it was given, not against another run's dropped frames (issue
/// 33 item 2): with both cores busy a full-speed run drops a few refreshes too.
/// How long `--slow-sim-ms` slows every simulation frame in the slow-solver runs, ms.
const SLOW_SIM_MS: f64 = 250.0;

#[test]
fn a_slow_solver_on_its_thread_costs_monado_no_display_frame() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let layers = monado::validation();
    let dir = temp_dir("xr-monado-slow");
    let run = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "xr",
            SCENE,
            "--frames",
            "40",
            "--device",
            "cpu",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let scratch = dir.join(format!("{name}-scratch"));
        let o = monado::run(manifest, &scratch, &args, layers);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", text(&o.stderr));
        assert_validation_clean(&o, &scratch, layers);
        let r = monado::report(&out, &o);
        assert_eq!(r["exit"], "Exited", "{name}: {r}");
        assert_eq!(r["frames"].as_u64(), Some(40), "{name}: {r}");
        let mut r = r;
        r["steady_dropped"] = steady_dropped(&out, &r).into();
        r
    };
    let base = run("base", &[]);
    let slow_ms = SLOW_SIM_MS.to_string();
    let slow = run("slow", &["--slow-sim-ms", &slow_ms]);
    let waits = run(
        "in-frame",
        &["--sim", "in-frame", "--slow-sim-ms", &slow_ms],
    );
    assert_eq!(base["sim_mode"], "thread", "the default: {base}");
    assert_eq!(waits["sim_mode"], "in-frame", "{waits}");
    for (name, r) in [
        ("full speed", &base),
        ("slow", &slow),
        ("slow in-frame", &waits),
    ] {
        let keys = [
            "frames",
            "rendered",
            "dropped_frames",
            "steady_dropped",
            "display_hz",
            "sim_frames",
            "sim_steps_per_s",
            "tool_latency_ms_p50_p95",
            "frame_ms_p50_p95",
        ];
        eprintln!(
            "{name}: {}",
            keys.map(|k| format!("{k} {}", r[k])).join(", ")
        );
    }
    // Monado stretches the period it predicts for an app that is late; a display that
    // never waits keeps the null compositor's 20 Hz. On its thread the slow solver holds
    // up no frame: 95 % of the frames take under half the slow step (8–53 ms measured
    // with both cores busy), and the display shows at least 3 frames per step (5 measured).
    let work = |r: &Value, q: usize| r["frame_ms_p50_p95"][q].as_f64().unwrap();
    for r in [&base, &slow] {
        assert!(num(r, "display_hz") > 15.0, "the display waited: {r}");
    }
    assert!(
        work(&slow, 1) < 0.5 * SLOW_SIM_MS,
        "the display waited for the slow solver: {slow}"
    );
    assert!(
        num(&slow, "frames") >= 3.0 * num(&slow, "sim_frames"),
        "the display showed few frames beside the slow solver: {slow}"
    );
    // Fewer steps, and the tissue shown lags the tool by at least the slow step.
    assert_slow_sim_steps_less_and_lags(&slow, &base);
    assert!(
        work(&waits, 0) >= SLOW_SIM_MS && num(&waits, "dropped_frames") > num(&waits, "frames"),
        "in-frame: {waits}"
    );
}

/// The GPU solver on the simulation thread gets its own device and queue: its compute
/// and waits do not hold up the renderer's submissions to the runtime's device (sharing
/// it, lavapipe made the display wait: 66 of 120 refreshes dropped).
#[test]
fn the_gpu_solver_on_its_thread_costs_monado_no_display_frame() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    // Without the Vulkan validation layer: on lavapipe it serialises the two devices'
    // pipeline compiles (a substep change rebuilds the GPU solver: about a second of
    // JIT), stalling the renderer for reasons of the emulated GPU, not of the thread.
    let layers = monado::Validation {
        vulkan: false,
        ..monado::validation()
    };
    let dir = temp_dir("xr-monado-gpu");
    let out = dir.join("out");
    let args = [
        "xr",
        SCENE,
        "--frames",
        "40",
        "--device",
        "gpu",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = monado::run(manifest, &dir, &args, layers);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_validation_clean(&o, &dir, layers);
    let r = monado::report(&out, &o);
    assert_eq!(r["sim_mode"], "thread", "{r}");
    assert!(
        r["solver_device"].as_str().unwrap().starts_with("gpu"),
        "{r}"
    );
    assert!(num(&r, "sim_frames") > 0.0, "{r}");
    assert!(
        num(&r, "display_hz") > 15.0 && steady_dropped(&out, &r) < 8.0,
        "the display waited for the GPU solver: {r}"
    );
}

/// Issue 20: a Nakao scene on the real runtime. Its body runs on its own thread (the
/// default for a real-time headset), the session renders into Monado's swapchains, ends
/// after `--frames` through EXITING, and the body's report (the run's schema) is written;
/// with a body slowed to 100 ms a frame, the display's own work per frame stays small.
#[test]
fn a_nakao_scene_on_monado_steps_its_body_on_a_thread() {
    let Some(manifest) = monado::monado() else {
        return;
    };
    let layers = monado::validation();
    let dir = temp_dir("xr-monado-nakao");
    let out = dir.join("out");
    let args = [
        "xr",
        "config/plate_cut_nakao.ron",
        "--frames",
        "30",
        "--slow-sim-ms",
        "100",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = monado::run(manifest, &dir, &args, layers);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_validation_clean(&o, &dir, layers);
    let stdout = text(&o.stdout);
    assert!(stdout.contains("on Monado"), "{stdout}");
    assert!(stdout.contains("body stepped thread"), "{stdout}");
    assert!(stdout.contains("30 display frames"), "{stdout}");
    let work: f64 = stdout
        .split("display frame work p50 ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no frame work in {stdout}"));
    assert!(work < 50.0, "the display waited for the body: {stdout}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["method"], "nakao", "{report}");
    assert!(!report["frames"].as_array().unwrap().is_empty(), "{report}");
}
