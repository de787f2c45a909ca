//! `incise xr` (issue 7): without a runtime it exits 2 with one paragraph of advice; on
//! the simulated headset the same frame loop renders both eyes at Quest 3 resolution
//! with the expected disparity, and the scripted controller stroke cuts the slab only
//! while the trigger holds the blade engaged, recording the stroke and a frame-time log.

mod common;

use std::path::Path;

use common::xr_report::{assert_slow_sim_steps_less_and_lags, latency_p50, num};
use common::{incise, score_stroke, temp_dir, text};
use glam::{Quat, Vec3};
use incise_xr::RgbaImage;
use serde_json::Value;

const SCRIPT: &str = "config/xr/plate_cut_headset.ron";

#[test]
fn without_a_runtime_incise_xr_exits_2_saying_what_is_missing() {
    let o = incise(&["xr", "config/plate_cut.ron"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let paragraph = err
        .lines()
        .find(|l| l.starts_with("incise xr needs an OpenXR runtime"))
        .unwrap_or_else(|| panic!("no message in: {err}"));
    // Either the loader is absent (this machine) or present without a runtime (CI with
    // libopenxr-loader1): the message names which.
    let loader_present = ["/usr/lib/x86_64-linux-gnu", "/usr/lib", "/usr/local/lib"]
        .iter()
        .any(|d| Path::new(d).join("libopenxr_loader.so.1").exists());
    if loader_present {
        assert!(
            paragraph.contains("no active OpenXR runtime"),
            "{paragraph}"
        );
    } else {
        assert!(
            paragraph.contains("OpenXR loader library") && paragraph.contains("libopenxr-loader1"),
            "{paragraph}"
        );
    }
    for needed in [
        "Meta Quest Link",
        "WiVRn",
        "docs/quest3.md",
        "incise preview config/plate_cut.ron",
    ] {
        assert!(paragraph.contains(needed), "missing {needed}: {paragraph}");
    }
}

/// Write `script_text` as a headset script and run `incise xr ARGS --simulated-headset
/// SCRIPT --out OUT` on it; the output and the output folder.
fn run_xr(
    name: &str,
    script_text: &str,
    args: &[&str],
) -> (std::process::Output, std::path::PathBuf) {
    let dir = temp_dir(name);
    let script = dir.join("headset.ron");
    std::fs::write(&script, script_text).unwrap();
    let out = dir.join("out");
    let mut all = vec!["xr"];
    all.extend_from_slice(args);
    all.extend([
        "--simulated-headset",
        script.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    (incise(&all), out)
}

/// The output folder's xr_report.json.
fn xr_report(out: &Path, o: &std::process::Output) -> Value {
    serde_json::from_str(
        &std::fs::read_to_string(out.join("xr_report.json"))
            .unwrap_or_else(|e| panic!("no xr_report.json ({e}): {}", text(&o.stderr))),
    )
    .unwrap()
}

fn run_simulated(name: &str, script_text: &str) -> (std::path::PathBuf, Value) {
    let (o, out) = run_xr(name, script_text, &["config/plate_cut.ron"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let report = xr_report(&out, &o);
    (out, report)
}

/// Centroid (x, y) of the pixels that differ from the corner (background) colour.
fn centroid(img: &RgbaImage) -> (f64, f64, usize) {
    let bg = img.get(0, 0);
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = img.get(x, y);
            if (0..3).any(|c| (p[c] as i32 - bg[c] as i32).abs() > 12) {
                sx += x as f64;
                sy += y as f64;
                n += 1;
            }
        }
    }
    (sx / n.max(1) as f64, sy / n.max(1) as f64, n)
}

#[test]
fn simulated_headset_renders_both_eyes_and_the_controller_stroke_cuts() {
    let script =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SCRIPT)).unwrap();
    let (out, r) = run_simulated("xr-sim", &script);
    assert_eq!(r["exit"], "Exited");
    assert_eq!(r["solver_resets"].as_u64(), Some(0), "{r}");
    // 2.8 s at 72 Hz on a 60 Hz simulation.
    assert_eq!(r["frames"].as_u64(), Some(202));
    let sim = r["sim_frames"].as_u64().unwrap();
    assert!((166..=169).contains(&sim), "{sim}");
    assert!(
        r["released_tets"].as_u64().unwrap() > 20,
        "the stroke cut: {r}"
    );
    assert!(r["max_tool_force"].as_f64().unwrap() > 0.05, "{r}");
    assert!(
        r["max_haptic"].as_f64().unwrap() > 0.0,
        "the controller vibrated: {r}"
    );
    // Frame-time log: a header and one row per display frame.
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!(csv.lines().count(), 203);
    // A display frame between simulation frames (one in six: 72 Hz on 60) keeps the
    // tissue's push and the controller's vibration; it does not drop them to zero.
    let column = |name: &str| {
        csv.lines()
            .next()
            .unwrap()
            .split(',')
            .position(|c| c == name)
    };
    let (sims, force, haptic) = (
        column("sim_frames").unwrap(),
        column("tool_force_n").unwrap(),
        column("haptic").unwrap(),
    );
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|c| c.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let mut held = 0;
    for w in rows.windows(2) {
        if w[1][sims] == 0.0 && w[0][force] > 0.0 {
            held += 1;
            assert_eq!(
                (w[1][force], w[1][haptic]),
                (w[0][force], w[0][haptic]),
                "a frame without a simulation step after {w:?}"
            );
        }
    }
    assert!(
        held >= 5,
        "{held} frames between simulation frames while cutting"
    );

    // The recorded stroke follows the incision line (x 1.5 → 5.5 cm at y = 2 cm).
    let stroke = incise_scalpel::load_stroke(&out.join("stroke.ron")).unwrap();
    assert!(stroke.keys().len() > 100);
    for k in stroke.keys() {
        assert!((k.position.y - 0.02).abs() < 1e-3, "{:?}", k.position);
        assert!((0.01..0.06).contains(&k.position.x), "{:?}", k.position);
    }

    // The trainee's stroke replays headless (`incise run --stroke`) to a cut of the same
    // size (the same tool path through the same solver; the session's frame timing
    // differs slightly).
    let o = incise(&[
        "run",
        "config/plate_cut.ron",
        "--stroke",
        out.join("stroke.ron").to_str().unwrap(),
        "--out",
        out.join("replay").to_str().unwrap(),
        "--vtu-every",
        "0",
        "--device",
        "cpu",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary = text(&o.stdout);
    let replayed: f64 = summary
        .split_whitespace()
        .zip(summary.split_whitespace().skip(1))
        .find(|(_, w)| *w == "tets")
        .and_then(|(n, _)| n.parse().ok())
        .unwrap_or_else(|| panic!("no tet count in {summary}"));
    let live = r["released_tets"].as_f64().unwrap();
    assert!(
        (replayed - live).abs() <= 0.1 * live,
        "replay {replayed} vs session {live}"
    );

    // Both eyes at Quest 3 size, showing the slab with the disparity of a 63 mm IPD.
    let left = RgbaImage::load_png(&out.join("eye_left_00000.png")).unwrap();
    let right = RgbaImage::load_png(&out.join("eye_right_00000.png")).unwrap();
    assert_eq!((left.width, left.height), (2064, 2208));
    assert_eq!(left.get(0, 0)[3], 255, "opaque room without passthrough");
    let (lx, ly, ln) = centroid(&left);
    let (rx, ry, rn) = centroid(&right);
    assert!(
        ln > 2000 && rn > 2000,
        "slab visible in both eyes: {ln} {rn}"
    );
    // Hand-computed: the slab's top centre on the tray is at stage (0, 0.92, −0.45)
    // (tray 0.9 m high, 0.45 m ahead; slab 2 cm thick); the head at (0, 1.25, −0.05)
    // pitched 40° down; eyes ±31.5 mm along the head's x; left eye fov (−0.87, 0.75),
    // the right eye mirrored. Pixel x = (tan θx − tan l) / (tan r − tan l) · width.
    let head_rot = Quat::from_xyzw(-0.34202, 0.0, 0.0, 0.93969).normalize();
    let head = Vec3::new(0.0, 1.25, -0.05);
    let p = Vec3::new(0.0, 0.92, -0.45);
    let px = |dx: f32, l: f32, r: f32| {
        let eye = head + head_rot * Vec3::new(dx, 0.0, 0.0);
        let d = head_rot.inverse() * (p - eye);
        let tan_x = d.x / -d.z;
        ((tan_x - l.tan()) / (r.tan() - l.tan()) * 2064.0) as f64
    };
    let expected_left = px(-0.0315, -0.87, 0.75);
    let expected_right = px(0.0315, -0.75, 0.87);
    let expected = expected_left - expected_right;
    let measured = lx - rx;
    assert!(expected > 300.0, "{expected}");
    assert!(
        (measured - expected).abs() < 0.02 * expected,
        "disparity {measured:.1} px, expected {expected:.1} px (left {lx:.1} vs {expected_left:.1}, right {rx:.1} vs {expected_right:.1})"
    );
    assert!((lx - expected_left).abs() < 25.0 && (rx - expected_right).abs() < 25.0);
    assert!((ly - ry).abs() < 2.0, "no vertical disparity: {ly} {ry}");
}

/// The same 2 mm deep stroke cuts with the trigger held and only pushes with it released.
/// The default organ (`config/intestine_pull.ron`, the implicit scheme) in the headset: a
/// trainee's scalpel pressed 3 mm into the bowel wall meets the tissue's force, and the
/// controller vibrates. Before the implicit scheme held the blade's nodes through its
/// solve, the force was about 2 mN and the controller never vibrated (threshold 0.05 N).
#[test]
fn the_default_organ_in_the_headset_pushes_back_on_the_scalpel() {
    let script = "(display_hz: 72.0, duration: 0.8, eye_size: (64, 64), render_every: 1000, \
        pacing: Nominal,\n head: [(t: 0.0, position: (0.0, 1.25, -0.05), \
        orientation: (-0.34202, 0.0, 0.0, 0.93969))],\n right: Some(Tool(start: 0.1, \
        stroke: Incision((start: (-0.05, 0.0, 0.03), end: (0.05, 0.0, 0.03), depth: 0.003, \
        speed: 0.02, approach: 0.005)))),\n trigger: [(0.0, 1.0)])";
    let (o, out) = run_xr(
        "xr-default-scalpel",
        script,
        &["config/intestine_pull.ron", "--device", "cpu"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = xr_report(&out, &o);
    assert_eq!(r["exit"], "Exited", "{r}");
    let force = r["max_tool_force"].as_f64().unwrap();
    assert!(force > 0.3, "the bowel pushes back on the blade: {force} N");
    let pulses = r["haptic_pulses"].as_u64().unwrap();
    assert!(
        pulses > 0 && r["max_haptic"].as_f64().unwrap() > 0.0,
        "the controller vibrated: {r}"
    );
    // Stepped in the frame, the body refactorises its coarse level after a frame's
    // releases once the display frame is handed over, before the next pose.
    assert_prepared_ahead(&out);
}

/// The frames of `out/report.json` after releases had their pose-free work done ahead
/// (`ahead_ms`, the implicit scheme's coarse refactorisation, `Solver::prepare_frame`).
fn assert_prepared_ahead(out: &Path) {
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let frames = report["frames"].as_array().unwrap();
    let count = |key: &str| frames.iter().filter(|f| num(f, key) > 0.0).count();
    let (released, ahead) = (count("released_now"), count("ahead_ms"));
    assert!(
        released > 1,
        "the blade should cut: {released} frames released tets"
    );
    assert!(
        ahead > 0,
        "no frame had its refactorisation done ahead ({released} frames released tets)"
    );
}

/// On its thread the simulation does the next frame's pose-free work right after it
/// publishes a frame, before it takes the next pose: on the shipped plate_cut (the
/// implicit scheme) a frame after releases finds its coarse refactorisation done.
#[test]
fn the_thread_refactorises_after_releases_before_the_next_pose() {
    let args = ["config/plate_cut.ron", "--sim", "thread", "--device", "cpu"];
    let (o, out) = run_xr("xr-rt-ahead", &realtime_script(), &args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(xr_report(&out, &o)["sim_mode"], "thread");
    assert_prepared_ahead(&out);
}

#[test]
fn with_the_trigger_released_the_blade_pushes_but_does_not_cut() {
    // Shallower than the other test's cut: a dull blade 5 mm deep inverts tets.
    let base = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SCRIPT))
        .unwrap()
        .replace("depth: 0.005", "depth: 0.002")
        .replace("screenshots: [0]", "screenshots: []");
    let (_, held) = run_simulated("xr-sim-held", &base);
    assert!(held["released_tets"].as_u64().unwrap() > 20, "{held}");
    let released = base.replace("trigger: [(0.0, 1.0)]", "trigger: [(0.0, 0.0)]");
    let (_, r) = run_simulated("xr-sim-released", &released);
    assert_eq!(r["exit"], "Exited");
    assert_eq!(r["solver_resets"].as_u64(), Some(0), "{r}");
    assert_eq!(r["released_tets"].as_u64(), Some(0), "{r}");
    // 0.046 N with the rest-free pair (0.05+ with the seed's softer γ-shifted pair).
    assert!(
        r["max_tool_force"].as_f64().unwrap() > 0.03,
        "the dull blade still pushes: {r}"
    );
    assert_eq!(
        r["max_haptic"].as_f64(),
        Some(0.0),
        "no vibration while disengaged: {r}"
    );
}

/// With passthrough the eye images are transparent around the organ (the room shows
/// through) and opaque on it.
#[test]
fn with_passthrough_the_room_shows_around_the_organ() {
    let (out, r) = run_simulated(
        "xr-sim-passthrough",
        "(duration: 0.03, eye_size: (320, 320), passthrough: true, screenshots: [0], \
         head: [(t: 0.0, position: (0.0, 1.25, -0.05), orientation: (-0.34202, 0.0, 0.0, 0.93969))])",
    );
    assert_eq!(r["exit"], "Exited");
    let eye = RgbaImage::load_png(&out.join("eye_left_00000.png")).unwrap();
    assert_eq!(
        eye.get(0, 0),
        [0, 0, 0, 0],
        "transparent, premultiplied background"
    );
    let opaque = (0..eye.height)
        .flat_map(|y| (0..eye.width).map(move |x| (x, y)))
        .filter(|&(x, y)| eye.get(x, y)[3] == 255)
        .count();
    assert!(opaque > 30, "the organ is opaque: {opaque} pixels");
}

/// The plate-cut script at a small eye size, drawing every 9th frame, with `fault`
/// injected 1 s in (0.9 s into the stroke); runs `incise xr` on it.
fn run_with_fault(name: &str, fault: &str) -> (std::process::Output, std::path::PathBuf) {
    let script = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SCRIPT))
        .unwrap()
        .replace("screenshots: [0]", "screenshots: []")
        .replace(
            "render_every: 1000,",
            &format!("render_every: 9, eye_size: (96, 96), faults: [(1.0, {fault})],"),
        );
    run_xr(name, &script, &["config/plate_cut.ron"])
}

/// Issue 11: a runtime that loses the session (LOSS_PENDING, or calls failing with
/// XR_ERROR_SESSION_LOST in the middle of a frame), goes away (instance loss) or ends the
/// session itself shuts incise down cleanly with the stroke, the frame log and the
/// report saved up to that moment; a runtime failure that is no clean end exits non-zero
/// and still keeps them.
#[test]
fn a_lost_or_ending_runtime_stops_the_session_cleanly_and_keeps_its_outputs() {
    for (fault, exit) in [
        ("SessionLoss", "SessionLost"),
        ("LostCall", "SessionLost"),
        ("InstanceLoss", "InstanceLost"),
        ("RuntimeExit", "Exited"),
        ("RuntimeFailure", "failed: "),
    ] {
        let (o, out) = run_with_fault(&format!("xr-fault-{fault}"), fault);
        let err = text(&o.stderr);
        let report = xr_report(&out, &o);
        let said = report["exit"].as_str().unwrap();
        assert!(said.starts_with(exit), "{fault}: exit {said}: {err}");
        if fault == "RuntimeFailure" {
            assert_eq!(o.status.code(), Some(1), "{fault}: {err}");
            assert!(
                err.contains("ERROR_RUNTIME_FAILURE") && err.contains("were kept"),
                "{fault}: {err}"
            );
        } else {
            assert!(o.status.success(), "{fault}: {err}");
        }
        // Stopped about 1 s in (72 display frames), not at the script's 2.8 s.
        let frames = report["frames"].as_u64().unwrap();
        assert!((70..=80).contains(&frames), "{fault}: {frames} frames");
        let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
        assert_eq!(csv.lines().count() as u64, frames + 1, "{fault}");
        assert!(
            report["released_tets"].as_u64().unwrap() > 0,
            "{fault}: {report}"
        );
        // The stroke up to the fault (session time 1 s), complete and readable.
        let stroke = incise_scalpel::load_stroke(&out.join("stroke.ron")).unwrap();
        assert!(
            (0.9..1.05).contains(&stroke.end_time()),
            "{fault}: stroke ends at {} s",
            stroke.end_time()
        );
    }
}

/// A headset script for the slab_depth exercise: the head 15 cm from the slab looking
/// down at it, then (1.7–1.9 s) raised to look ahead over the tray; the right controller
/// draws the exercise's reference stroke from 0.1 s with the trigger held; then `extra`
/// (buttons, faults, screenshots) — eyes 480 px square, every 12th frame drawn.
fn exercise_script(duration: f64, extra: &str) -> String {
    stroke_script("slab_depth_reference.ron", duration, extra)
}

/// [`exercise_script`] with the right controller drawing `config/strokes/STROKE`.
fn stroke_script(stroke: &str, duration: f64, extra: &str) -> String {
    let stroke = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("config/strokes")
        .join(stroke);
    format!(
        "(duration: {duration}, eye_size: (480, 480), render_every: 12, pacing: Nominal, \
         head: [(t: 0.0, position: (0.0, 1.02, -0.36), orientation: (-0.42262, 0.0, 0.0, 0.90631)), \
                (t: 1.7, position: (0.0, 1.02, -0.36), orientation: (-0.42262, 0.0, 0.0, 0.90631)), \
                (t: 1.9, position: (0.0, 1.25, -0.05), orientation: (-0.08716, 0.0, 0.0, 0.99619))], \
         right: Some(Tool(start: 0.1, stroke: File({:?}))), trigger: [(0.0, 1.0)], {extra})",
        stroke.to_str().unwrap()
    )
}

/// Run `incise xr --exercise slab_depth` on `script`; the output folder and xr_report.json.
fn run_exercise_session(
    name: &str,
    script: &str,
    extra: &[&str],
) -> (std::path::PathBuf, Value, std::process::Output) {
    run_exercise_on("config/exercises/slab_depth.ron", name, script, extra)
}

/// [`run_exercise_session`] on the exercise file `exercise`.
fn run_exercise_on(
    exercise: &str,
    name: &str,
    script: &str,
    extra: &[&str],
) -> (std::path::PathBuf, Value, std::process::Output) {
    // The history goes into the output folder (created by incise).
    let out_dir = std::env::temp_dir()
        .join(format!("incise-e2e-{}-{name}", std::process::id()))
        .join("out");
    let history = out_dir.join("history.jsonl");
    let mut args = vec![
        "--exercise",
        exercise,
        "--history",
        history.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (o, out) = run_xr(name, script, &args);
    assert_eq!(out, out_dir);
    let report = xr_report(&out, &o);
    (out, report, o)
}

/// Pixels of the plan's violet ink (sRGB #6A1B9A-ish: blue and red well above green,
/// unlike the pink skin, the red cut and the grey tool).
fn plan_pixels(img: &RgbaImage) -> usize {
    (0..img.height)
        .flat_map(|y| (0..img.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get(x, y).map(i32::from);
            p[2] > p[1] + 30 && p[0] > p[1] + 10
        })
        .count()
}

/// Pixels of the result card's paper colour (sRGB 250, 250, 247).
fn card_pixels(img: &RgbaImage) -> usize {
    (0..img.height)
        .flat_map(|y| (0..img.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get(x, y);
            (p[0] as i32 - 250).abs() <= 4
                && (p[1] as i32 - 250).abs() <= 4
                && (p[2] as i32 - 247).abs() <= 4
        })
        .count()
}

/// Issue 10 in the headset: the plan is drawn on the tissue, A finishes the attempt
/// (scored as `incise exercise` scores its recorded stroke, saved, appended to the
/// history) and hangs the result card above the tray.
#[test]
fn an_exercise_in_the_headset_is_scored_on_a_and_shows_its_card() {
    // Stroke 0.1–1.37 s; A at 1.8 s; eyes saved at frames 36 (0.5 s: the line is still
    // mostly uncut) and 144 (2.0 s).
    let (out, r, o) = run_exercise_session(
        "xr-exercise",
        &exercise_script(2.2, "buttons: [(1.8, A)], screenshots: [36, 144]"),
        &[],
    );
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_eq!(r["exit"], "Exited", "{r}");
    let attempts = r["attempts"].as_array().unwrap();
    assert_eq!(attempts.len(), 1, "{r}");
    let a = &attempts[0];
    assert_eq!(a["ended_by"], "A pressed");
    assert_eq!(a["passed"], true, "{a}: {err}");
    let dir = std::path::PathBuf::from(a["dir"].as_str().unwrap());
    for f in ["result.json", "report.html", "stroke.ron", "card.png"] {
        assert!(dir.join(f).exists(), "{f} missing in {}", dir.display());
    }
    let history = std::fs::read_to_string(out.join("history.jsonl")).unwrap();
    assert_eq!(history.lines().count(), 1);

    // The plan is drawn while cutting (violet ink, sRGB #6A1B9A-ish: blue and red well
    // above green, unlike the pink skin, the red cut and the grey tool) and the card only
    // after A.
    let before = RgbaImage::load_png(&out.join("eye_left_00036.png")).unwrap();
    let after = RgbaImage::load_png(&out.join("eye_left_00144.png")).unwrap();
    let violet = plan_pixels;
    assert!(
        violet(&before) > 10,
        "plan drawn: {} violet pixels",
        violet(&before)
    );
    assert!(
        card_pixels(&before) < 20,
        "no card before A: {}",
        card_pixels(&before)
    );
    assert!(
        card_pixels(&after) > 500,
        "card after A: {}",
        card_pixels(&after)
    );
    for eye in ["left", "right"] {
        let img = RgbaImage::load_png(&out.join(format!("eye_{eye}_00144.png"))).unwrap();
        assert!(card_pixels(&img) > 500, "{eye} eye sees the card");
    }

    // The live score is what `incise exercise` gives the attempt's recorded stroke.
    let (_, replayed) = assert_replay_scores_alike("config/exercises/slab_depth.ron", &dir, &out);
    assert_eq!(replayed["verdict"]["passed"], true);
}

/// `incise exercise` on the stroke an attempt in `dir` recorded scores it within 2
/// points of the live score; both results.
fn assert_replay_scores_alike(exercise: &str, dir: &Path, out: &Path) -> (Value, Value) {
    let json =
        |p: &Path| -> Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    let live = json(&dir.join("result.json"));
    let replay = out.join("replay");
    let history = out.join("replay_history.jsonl");
    score_stroke(exercise, &dir.join("stroke.ron"), &replay, &history);
    let replayed = json(&replay.join("result.json"));
    let (s1, s2) = (
        live["verdict"]["score"].as_f64().unwrap(),
        replayed["verdict"]["score"].as_f64().unwrap(),
    );
    assert!((s1 - s2).abs() < 2.0, "live {s1} vs replay {s2}");
    (live, replayed)
}

/// Issue 10 and 11: an attempt under way when the session is lost is still scored and
/// saved.
#[test]
fn an_attempt_under_way_is_saved_when_the_session_is_lost() {
    let (_, r, o) = run_exercise_session(
        "xr-exercise-lost",
        &exercise_script(3.0, "faults: [(1.6, SessionLoss)]"),
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(r["exit"], "SessionLost", "{r}");
    let attempts = r["attempts"].as_array().unwrap();
    assert_eq!(attempts.len(), 1, "{r}");
    assert_eq!(attempts[0]["ended_by"], "session ended");
    let dir = std::path::PathBuf::from(attempts[0]["dir"].as_str().unwrap());
    assert!(dir.join("result.json").exists());
}

/// A solver failure mid-attempt (a NaN injected at simulation frame 45, 0.75 s: the blade
/// is in the tissue) rolls the frame back; the attempt is scored and saved as it stood,
/// the scene reset, and the rest of the stroke is a second attempt saved at the end.
#[test]
fn a_solver_failure_saves_the_attempt_before_the_scene_is_reset() {
    let (_, r, o) = run_exercise_session(
        "xr-exercise-nan",
        &exercise_script(2.0, ""),
        &["--inject-nan-at", "45"],
    );
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_eq!(r["solver_resets"].as_u64(), Some(1), "{r}");
    let attempts = r["attempts"].as_array().unwrap();
    assert_eq!(attempts.len(), 2, "{r}");
    let first = attempts[0]["ended_by"].as_str().unwrap();
    assert!(
        first.starts_with("solver failed") && first.contains("frame"),
        "{first}"
    );
    assert_eq!(attempts[1]["ended_by"], "session ended");
    for a in attempts {
        let dir = std::path::PathBuf::from(a["dir"].as_str().unwrap());
        assert!(dir.join("result.json").exists() && dir.join("stroke.ron").exists());
    }
}

/// A session that ends after a single simulation frame has no stroke to save (a stroke
/// needs two poses): it still ends cleanly with its report (found by Ctrl-C at once on
/// Monado, where it failed with "a stroke needs at least 2 poses" and wrote no report).
#[test]
fn a_session_of_one_simulation_frame_writes_its_report_without_a_stroke() {
    let script = r#"(
        display_hz: 72.0,
        duration: 0.02,
        eye_size: (64, 64),
        render_every: 1000,
        pacing: Nominal,
        head: [(t: 0.0, position: (0.0, 1.25, -0.05), orientation: (-0.34202, 0.0, 0.0, 0.93969))],
        right: Some(Tool(
            start: 0.0,
            stroke: Incision((start: (0.015, 0.02, 0.02), end: (0.055, 0.02, 0.02), depth: 0.005, speed: 0.02, approach: 0.005)),
        )),
    )"#;
    let (o, out) = run_xr("xr-one-frame", script, &["config/plate_cut.ron"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = xr_report(&out, &o);
    assert_eq!(r["sim_frames"].as_u64(), Some(1), "{r}");
    assert_eq!(r["exit"], "Exited");
    assert!(r["stroke"].is_null(), "{r}");
    assert!(!out.join("stroke.ron").exists());
}

/// A 0.25 s plate-cut session on the virtual clock, 64 px eyes every frame, with
/// `draw_eyes` as given (and `extra` fields).
fn eyes_script(draw: bool, extra: &str) -> String {
    format!(
        "(display_hz: 72.0, duration: 0.25, eye_size: (64, 64), render_every: 1, \
         draw_eyes: {draw}, {extra}
         head: [(t: 0.0, position: (0.0, 1.25, -0.05), orientation: (-0.34202, 0.0, 0.0, 0.93969))])"
    )
}

/// `draw_eyes: false` (the headset benchmark's "not drawn" rows): every frame is still
/// shown, with its tool-to-tissue latency, but none is drawn; drawn, every shown one is.
/// A screenshot asked of undrawn eyes is refused, naming the field.
#[test]
fn eyes_left_undrawn_still_show_every_frame_and_its_latency() {
    for draw in [false, true] {
        let (o, out) = run_xr(
            &format!("xr-draw-{draw}"),
            &eyes_script(draw, ""),
            &["config/plate_cut.ron"],
        );
        assert!(o.status.success(), "{}", text(&o.stderr));
        let r = xr_report(&out, &o);
        assert_eq!(r["frames"].as_u64(), Some(18), "{r}");
        assert_eq!(r["rendered"].as_u64(), Some(18), "{r}");
        let drawn = if draw { 18 } else { 0 };
        assert_eq!(r["drawn"].as_u64(), Some(drawn), "{r}");
        // In-frame on the virtual clock: a frame shows its own step (0 ms) or the last.
        assert!(latency_p50(&r) >= 0.0, "{r}");
        let described = r["headset"].as_str().unwrap().contains("not drawn");
        assert_eq!(described, !draw, "{r}");
    }
    let (o, _) = run_xr(
        "xr-draw-shot",
        &eyes_script(false, "screenshots: [3],"),
        &["config/plate_cut.ron"],
    );
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("headset.ron") && err.contains("screenshots") && err.contains("draw_eyes"),
        "{err}"
    );
}

/// The plate-cut script on the wall clock (a frame that comes late skips the refreshes
/// it missed, as on a runtime), 64 px eyes drawn every frame, substeps paced as on a
/// headset.
fn realtime_script() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SCRIPT))
        .unwrap()
        .replace("screenshots: [0]", "screenshots: []")
        .replace("pacing: Nominal,", "")
        .replace(
            "render_every: 1000,",
            "render_every: 1, eye_size: (64, 64), realtime: true,",
        )
}

/// `incise xr` on [`realtime_script`] with `args`.
fn run_realtime(name: &str, args: &[&str]) -> (std::process::Output, std::path::PathBuf) {
    run_realtime_on(name, &realtime_script(), args)
}

/// `incise xr` on `script` (a [`realtime_script`] changed) with `args`.
fn run_realtime_on(
    name: &str,
    script: &str,
    args: &[&str],
) -> (std::process::Output, std::path::PathBuf) {
    // plate_cut on XPBD: these runs time the session's threads against a slowed solver,
    // and were set on XPBD's frame (on the implicit scheme, which the shipped scene runs,
    // the in-frame run's last frames outlast the script's end: 144 refreshes shown).
    let scene = common::scene_on_scheme("plate_cut.ron", "Xpbd", &format!("{name}-scene"));
    let mut all = vec![scene.to_str().unwrap()];
    all.extend_from_slice(args);
    run_xr(name, script, &all)
}

/// The report's figures of issue 19 item 3.
const SUMMARY_KEYS: [&str; 7] = [
    "frames",
    "rendered",
    "dropped_frames",
    "sim_frames",
    "sim_steps_per_s",
    "tool_latency_ms_p50_p95",
    "frame_ms_p50_p95",
];

/// How long `--slow-sim-ms` slows every simulation frame in the real-time runs, ms.
const SLOW_SIM_MS: f64 = 250.0;

/// Issue 19 item 3: with the solver on its own thread, a solver slowed by 250 ms a frame
/// costs the display no frame: the display's own work per frame stays far under the slow
/// step and it shows many frames for each simulation step, while the simulation's steps
/// per second fall below 4 and the tissue lags the tool by at least that step. The same
/// slowness inside the frame loop makes every display frame wait for it. Each run is
/// judged on its own measures against the slowness it was given (issue 33 item 2), so
/// the margins hold with both cores busy: a frame that waits for the solver takes
/// ≥ 250 ms on any machine, one that does not takes its own drawing time.
#[test]
fn a_slow_solver_on_its_thread_costs_the_realtime_headset_no_frame() {
    let run = |name: &str, args: &[&str]| {
        let (o, out) = run_realtime(name, args);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let r = xr_report(&out, &o);
        assert_eq!(r["exit"], "Exited", "{name}: {r}");
        r
    };
    let slow_ms = SLOW_SIM_MS.to_string();
    let base = run("xr-rt-base", &["--sim", "thread"]);
    let slow = run(
        "xr-rt-slow",
        &["--sim", "thread", "--slow-sim-ms", &slow_ms],
    );
    let waits = run(
        "xr-rt-in-frame",
        &["--sim", "in-frame", "--slow-sim-ms", &slow_ms],
    );
    assert_eq!(base["sim_mode"], "thread", "{base}");
    assert_eq!(waits["sim_mode"], "in-frame", "{waits}");
    assert_eq!(slow["slow_sim_ms"].as_f64(), Some(SLOW_SIM_MS), "{slow}");
    for (name, r) in [
        ("full speed", &base),
        ("slow", &slow),
        ("slow in-frame", &waits),
    ] {
        eprintln!(
            "{name}: {}",
            SUMMARY_KEYS.map(|k| format!("{k} {}", r[k])).join(", ")
        );
    }
    // 2.8 s at 72 Hz, less the last frames' length (up to 0.6 s when a frame waits for
    // the solver): every refresh is a display frame or a dropped one.
    for r in [&base, &slow, &waits] {
        let shown = num(r, "frames") + num(r, "dropped_frames");
        assert!((150.0..=204.0).contains(&shown), "{shown} refreshes: {r}");
    }
    let work_p95 = |r: &serde_json::Value| r["frame_ms_p50_p95"][1].as_f64().unwrap();
    let work_p50 = |r: &serde_json::Value| r["frame_ms_p50_p95"][0].as_f64().unwrap();
    // On its thread the slow solver holds up no display frame: 95 % of the frames take
    // under half the slow step (a 64 px frame takes a few ms), and the display shows at
    // least 5 frames for each simulation step (≤ 4 steps/s against a display that drops
    // only frames its own drawing overran).
    assert!(
        work_p95(&slow) < 0.5 * SLOW_SIM_MS,
        "the display waited for the slow solver: {slow}"
    );
    assert!(
        num(&slow, "frames") >= 5.0 * num(&slow, "sim_frames"),
        "the display showed few frames beside the slow solver: {slow}"
    );
    // Fewer steps, and the tissue shown lags the tool by at least the slow step.
    assert_slow_sim_steps_less_and_lags(&slow, &base);
    assert_eq!(
        latency_p50(&waits),
        0.0,
        "in the frame the tissue keeps up: {waits}"
    );
    // Stepping the slow solver inside the frame makes the display wait: each frame takes
    // the slow step and the refreshes it spans drop (≥ 17 of every 18 at 72 Hz).
    assert!(work_p50(&waits) >= SLOW_SIM_MS, "in-frame: {waits}");
    let refreshes = num(&waits, "frames") + num(&waits, "dropped_frames");
    assert!(
        num(&waits, "dropped_frames") >= 0.8 * refreshes,
        "in-frame: {} of {refreshes} refreshes dropped",
        num(&waits, "dropped_frames")
    );
}

/// On the simulation thread, a solver failure (a NaN before simulation frame 4) resets
/// the scene and the session goes on; a panic (before frame 12) ends the session with a
/// clear error, exit 1, and the report, frame log and stroke kept. (Early frames: on two
/// shared cores the thread may step only a few a second.) In the panicking run the
/// controller is tracked from the display's first frame, so each of the 12 frames records
/// a pose whatever the display's pace: with the script's 0.1 s of untracked controller, a
/// display slowed by a busy machine could leave the thread stepping all 12 on untracked
/// commands, and no stroke to keep.
#[test]
fn a_failing_or_panicking_simulation_thread_keeps_the_outputs() {
    let (o, out) = run_realtime("xr-rt-nan", &["--sim", "thread", "--inject-nan-at", "4"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = xr_report(&out, &o);
    assert_eq!(r["solver_resets"].as_u64(), Some(1), "{r}");
    assert_eq!(r["exit"], "Exited", "{r}");

    let tracked_at_once = realtime_script().replace("start: 0.1,", "start: 0.0,");
    assert_ne!(
        tracked_at_once,
        realtime_script(),
        "the tool's start is in the script"
    );
    let (o, out) = run_realtime_on(
        "xr-rt-panic",
        &tracked_at_once,
        &["--sim", "thread", "--inject-sim-panic-at", "12"],
    );
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the simulation thread panicked: injected panic before simulation frame 12")
            && err.contains("were kept"),
        "{err}"
    );
    let r = xr_report(&out, &o);
    assert!(
        r["exit"]
            .as_str()
            .unwrap()
            .starts_with("failed: the simulation thread panicked"),
        "{r}"
    );
    assert_eq!(r["sim_frames"].as_u64(), Some(12), "{r}");
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!(
        csv.lines().count() as u64,
        r["frames"].as_u64().unwrap() + 1
    );
    // A pose from each frame stepped before the panic.
    let stroke = incise_scalpel::load_stroke(&out.join("stroke.ron")).unwrap();
    assert_eq!(stroke.keys().len(), 12, "the stroke up to the panic");
}

/// A Nakao exercise in the headset: the body stepped in the frame, the blade the
/// controller's from the start (the plate's scripted cut does not run), the plan drawn
/// on the plate, A finishes the attempt, scored on the cut surface as `incise exercise`
/// scores its recorded stroke, and hangs the card.
#[test]
fn a_nakao_exercise_in_the_headset_is_scored_on_its_cut_surface() {
    // The reference stroke runs 0.1–3.5 s; A at 3.7 s; eyes saved at frames 72 (1 s) and
    // 276 (3.83 s).
    let script = stroke_script(
        "plate_line_nakao_reference.ron",
        4.0,
        "buttons: [(3.7, A)], screenshots: [72, 276]",
    );
    let exercise = "config/exercises/plate_line_nakao.ron";
    let (out, r, o) = run_exercise_on(exercise, "xr-exercise-nakao", &script, &[]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_eq!(
        (r["method"].as_str(), r["sim_mode"].as_str()),
        (Some("nakao"), Some("in-frame")),
        "{r}"
    );
    let attempts = r["attempts"].as_array().unwrap();
    assert_eq!(attempts.len(), 1, "{r}");
    assert_eq!(attempts[0]["ended_by"], "A pressed");
    assert_eq!(attempts[0]["passed"], true, "{}: {err}", attempts[0]);
    let dir = std::path::PathBuf::from(attempts[0]["dir"].as_str().unwrap());
    let (live, _) = assert_replay_scores_alike(exercise, &dir, &out);
    assert_eq!(live["method"], "nakao");
    assert!(
        live["metrics"]["cut_faces"].as_u64().unwrap() > 20,
        "{}",
        live["metrics"]
    );
    let before = RgbaImage::load_png(&out.join("eye_left_00072.png")).unwrap();
    let after = RgbaImage::load_png(&out.join("eye_left_00276.png")).unwrap();
    let violet = plan_pixels(&before);
    assert!(violet > 10, "plan drawn: {violet} violet pixels");
    assert!(
        card_pixels(&before) < 20 && card_pixels(&after) > 500,
        "card {} / {}",
        card_pixels(&before),
        card_pixels(&after)
    );
}

/// `incise xr --exercise EXERCISE` on `script` with its trigger let go from `up` to
/// `down` s (the script's trigger is linear between keys: a step takes two keys 10 ms
/// apart), then the one attempt's replay: the span the recorded stroke is lifted over
/// (one, where the trigger was up) checked, and the live and replayed results.
fn attempt_with_the_trigger_let_go(
    exercise: &str,
    name: &str,
    script: &str,
    (up, down): (f64, f64),
) -> (Value, Value) {
    let script = script.replace(
        "trigger: [(0.0, 1.0)]",
        &format!(
            "trigger: [(0.0, 1.0), ({}, 1.0), ({up}, 0.0), ({}, 0.0), ({down}, 1.0)]",
            up - 0.01,
            down - 0.01
        ),
    );
    let (out, r, o) = run_exercise_on(exercise, name, &script, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let attempts = r["attempts"].as_array().unwrap();
    assert_eq!(attempts.len(), 1, "{r}");
    let dir = std::path::PathBuf::from(attempts[0]["dir"].as_str().unwrap());
    let stroke = incise_scalpel::load_stroke(&dir.join("stroke.ron")).unwrap();
    let lifted = stroke.lifted().to_vec();
    assert_eq!(lifted.len(), 1, "{lifted:?}");
    let (from, to) = lifted[0];
    eprintln!("trigger up {up}-{down} s, stroke lifted {from}-{to} s");
    assert!(
        (from - up).abs() < 0.05 && (to - down).abs() < 0.05,
        "{lifted:?}"
    );
    assert_replay_scores_alike(exercise, &dir, &out)
}

/// A Nakao attempt in the headset with the trigger let go for a second mid-stroke (1.2 to
/// 2.2 s, the blade still in the plate): the live cut pauses there, the recorded stroke
/// is lifted over that second, and its replay (`incise exercise --stroke`) cuts the same
/// surface, face for face, instead of cutting all along.
#[test]
fn a_nakao_attempt_with_the_trigger_let_go_replays_its_cut() {
    let script = stroke_script(
        "plate_line_nakao_reference.ron",
        4.0,
        "buttons: [(3.7, A)], screenshots: []",
    );
    let (live, replayed) = attempt_with_the_trigger_let_go(
        "config/exercises/plate_line_nakao.ron",
        "xr-exercise-nakao-lifted",
        &script,
        (1.2, 2.2),
    );
    let faces = |v: &Value| v["metrics"]["cut_faces"].as_u64().unwrap();
    eprintln!(
        "cut faces: live {}, replay {}",
        faces(&live),
        faces(&replayed)
    );
    assert!(faces(&live) > 10, "{}", live["metrics"]);
    assert_eq!(
        faces(&live),
        faces(&replayed),
        "live {live}\nreplay {replayed}"
    );
    assert_eq!(
        live["metrics"]["cut_area"], replayed["metrics"]["cut_area"],
        "live {live}\nreplay {replayed}"
    );
}

/// The same for an XPBD attempt (slab_depth): the trigger let go 0.5 to 0.9 s into the
/// session, the blade in the slab, dulls it live (it pushes, cuts nothing); the recorded
/// stroke is lifted there and its replay dulls the blade there too, releasing the live
/// attempt's tets.
#[test]
fn an_xpbd_attempt_with_the_trigger_let_go_replays_its_cut() {
    let (live, replayed) = attempt_with_the_trigger_let_go(
        "config/exercises/slab_depth.ron",
        "xr-exercise-xpbd-lifted",
        &exercise_script(2.2, "buttons: [(1.8, A)], screenshots: []"),
        (0.5, 0.9),
    );
    let released = |v: &Value| v["metrics"]["released_tets"].as_u64().unwrap();
    eprintln!(
        "released tets: live {}, replay {}",
        released(&live),
        released(&replayed)
    );
    assert!(released(&live) > 10, "{}", live["metrics"]);
    assert_eq!(
        released(&live),
        released(&replayed),
        "live {live}\nreplay {replayed}"
    );
}
