//! An exercise attempt in the preview without a window (issue 10): the preview's attempt
//! logic (one for every method: `PreviewHand`, a `RecordedBody`, `PreviewExercise`) runs
//! an exercise with its reference stroke driving the scalpel, finishes, scores the live
//! body and saves the attempt; `incise exercise` on the recorded stroke.ron then gives the
//! same score, from the same released tets (XPBD: the CPU solver is deterministic, and
//! the stroke replays bit for bit) or the same cut surface (Nakao).

mod common;

use std::path::Path;

use common::{score_stroke, temp_dir};
use incise::exercise::live::attempt_pictures;
use incise::exercise::{Finished, ToolFrame};
use incise::pictures::screenshots::default_camera;
use incise::preview::PreviewExercise;
use incise::preview::hand::PreviewHand;
use incise::preview::live::preview_options;
use incise::sim_body::DeviceChoice;
use incise::sim_body::recorded::RecordedBody;
use serde_json::Value;

const EXERCISE: &str = "config/exercises/slab_depth.ron";

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The exercise's scene as the preview opens it (on the CPU), and the mouse's hand on it.
fn preview_body(mode: &PreviewExercise) -> (RecordedBody, PreviewHand) {
    let opts = preview_options(DeviceChoice::Cpu, None);
    let body = RecordedBody::open_with(mode.scene_path(), &opts).unwrap();
    let mesh = mode.exercise.mesh.clone();
    let tool = body.scalpel().unwrap();
    let hand = PreviewHand::new(tool, &body, mesh.rest_bounds(), default_camera(&mesh).yaw);
    (body, hand)
}

/// "Watch the reference" for `frames` frames, then Finish: the attempt as the preview
/// makes it, and whether its report has pictures.
fn reference_attempt(
    mode: &mut PreviewExercise,
    frames: impl Fn(f64, f64) -> u64,
    (out_root, history): (&Path, &Path),
) -> (Finished, RecordedBody, bool) {
    let (mut body, mut hand) = preview_body(mode);
    let reference = mode.reference().unwrap();
    let frames = frames(reference.end_time(), body.body.frame_dt());
    hand.play(reference);
    // Pictures for the report when an offscreen renderer exists (lavapipe will do).
    let pictures = attempt_pictures(&body, &mode.decal);
    let rendered = pictures.is_ok();
    mode.start(&mut hand, &mut body, pictures).unwrap();
    assert_eq!(mode.running(), Some(0));
    assert!(!mode.touched());
    for _ in 0..frames {
        let tool = hand.tool_input(&body).unwrap();
        body.step(&tool).unwrap();
        hand.after_step(&body);
        mode.after_step(ToolFrame::of(body.last_frame().unwrap()));
    }
    assert!(mode.touched(), "the blade never touched the tissue");
    assert_eq!(mode.running(), Some(frames as usize));
    let done = mode.finish(&mut hand, &body, out_root, history).unwrap();
    assert_eq!(mode.running(), None);
    // A second finish has nothing to finish.
    assert!(mode.finish(&mut hand, &body, out_root, history).is_err());
    (done, body, rendered)
}

#[test]
fn a_preview_attempt_scores_as_incise_exercise_does_on_its_stroke() {
    let dir = temp_dir("preview-exercise");
    let history = dir.join("history.jsonl");
    let out_root = dir.join("out/exercises");
    let mut mode = PreviewExercise::open(Path::new(EXERCISE)).unwrap();
    let until = |end: f64, dt: f64| ((end + 0.2) / dt).ceil() as u64;
    let (done, body, rendered) = reference_attempt(&mut mode, until, (&out_root, &history));
    let frames = body.frames() as u64;
    let solver = body.body.solver_parts().unwrap().body.solver();
    let live_released: Vec<u64> = (0..solver.mesh().tet_count())
        .filter(|&t| !solver.cut().is_live(t))
        .map(|t| t as u64)
        .collect();
    assert!(done.dir.starts_with(&out_root));
    assert!(
        done.dir
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with("slab_depth-"),
        "{}",
        done.dir.display()
    );

    // result.json parses and is the attempt's; the history gained one line; the card.
    let live = json(&done.attempt.result_path);
    assert_eq!(live["exercise"], "slab_depth");
    assert_eq!(live["frames"], frames);
    let live_score = live["verdict"]["score"].as_f64().unwrap();
    assert_eq!(live_score, done.attempt.result.verdict.score);
    assert_eq!(live["verdict"]["passed"], true, "{}", live["verdict"]);
    assert!(done.attempt.html_path.is_file());
    let html = std::fs::read_to_string(&done.attempt.html_path).unwrap();
    assert_eq!(
        html.contains("No pictures"),
        !rendered,
        "pictures in the report iff a renderer was given"
    );
    assert!(done.stroke.is_file());
    let lines = std::fs::read_to_string(&history).unwrap();
    assert_eq!(lines.lines().count(), 1, "{lines}");
    let standing = done.standing.expect("the history is readable");
    assert_eq!(standing.attempts, 1);
    assert_eq!(standing.best, live_score);
    assert_eq!(
        (done.card.width, done.card.height),
        incise::exercise::CARD_SIZE
    );
    assert!(done.dir.join("card.png").is_file());

    // `incise exercise` on the saved stroke: the same score from the same tets.
    let replay = dir.join("replay");
    score_stroke(EXERCISE, &done.stroke, &replay, &history);
    let cli = json(&replay.join("result.json"));
    let report = json(&replay.join("report.json"));
    let cli_released: Vec<u64> = report["released_tets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(
        cli_released, live_released,
        "the replay released other tets"
    );
    let cli_score = cli["verdict"]["score"].as_f64().unwrap();
    eprintln!(
        "live score {live_score:.3} ({frames} frames), incise exercise {cli_score:.3} ({} frames), {} tets released",
        cli["frames"],
        live_released.len()
    );
    assert!(
        (cli_score - live_score).abs() < 1e-6,
        "live {live_score} vs incise exercise {cli_score}"
    );
    for key in [
        "completion",
        "mean_deviation",
        "max_depth",
        "max_force",
        "duration",
    ] {
        assert_eq!(cli["metrics"][key], live["metrics"][key], "{key}");
    }
    assert_eq!(
        std::fs::read_to_string(&history).unwrap().lines().count(),
        2
    );
}

/// The preview's attempt on the Nakao plate exercise, without a window: the reference
/// stroke moves the blade (engaged), the attempt records its pose each frame and is
/// scored on the body's cut surface; `incise exercise` on the recorded stroke.ron cuts
/// the same surface and gives the same score.
#[test]
fn a_preview_attempt_on_a_nakao_exercise_scores_as_incise_exercise_does() {
    const NAKAO: &str = "config/exercises/plate_line_nakao.ron";
    let dir = temp_dir("preview-exercise-nakao");
    let history = dir.join("history.jsonl");
    let mut mode = PreviewExercise::open(Path::new(NAKAO)).unwrap();
    let until = |end: f64, dt: f64| (end / dt).ceil() as u64;
    let out_root = dir.join("out/exercises");
    let (done, _, _) = reference_attempt(&mut mode, until, (&out_root, &history));
    let live = json(&done.attempt.result_path);
    assert_eq!(
        (live["method"].as_str(), live["verdict"]["passed"].as_bool()),
        (Some("nakao"), Some(true)),
        "{}",
        live["verdict"]
    );
    let replay = dir.join("replay");
    score_stroke(NAKAO, &done.stroke, &replay, &history);
    let cli = json(&replay.join("result.json"));
    for key in [
        "cut_faces",
        "cut_area",
        "completion",
        "mean_deviation",
        "max_depth",
    ] {
        assert_eq!(cli["metrics"][key], live["metrics"][key], "{key}");
    }
    let (a, b) = (
        live["verdict"]["score"].as_f64().unwrap(),
        cli["verdict"]["score"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 0.5, "live {a} vs incise exercise {b}");
    assert!(done.dir.join("card.png").is_file() && done.attempt.html_path.is_file());
}
