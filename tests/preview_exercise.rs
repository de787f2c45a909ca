//! An exercise attempt in the preview without a window (issue 10): the preview's attempt
//! logic runs slab_depth.ron with its reference stroke driving the scalpel, finishes,
//! scores the live body and saves the attempt; `incise exercise` on the recorded
//! stroke.ron then gives the same score, from the same released tets (the CPU solver is
//! deterministic, and the stroke replays bit for bit).

mod common;

use std::path::Path;

use common::{score_stroke, temp_dir};
use incise::exercise::LiveExercise;
use incise::pictures::screenshots::{ImageSize, Screenshots, default_camera};
use incise::preview::hand_tool::HandTool;
use incise::scene::{ToolDriver, build_scene_driven};
use incise::sim_body::Body;
use serde_json::Value;

const EXERCISE: &str = "config/exercises/slab_depth.ron";

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn a_preview_attempt_scores_as_incise_exercise_does_on_its_stroke() {
    let dir = temp_dir("preview-exercise");
    let history = dir.join("history.jsonl");
    let mut mode = LiveExercise::open(Path::new(EXERCISE)).unwrap();
    let scene = incise::scene::load_scene(mode.scene_path()).unwrap();
    let mut built = build_scene_driven(&scene, mode.scene_path(), None, ToolDriver::Hand).unwrap();
    let camera = default_camera(built.solver.mesh());
    let mut hand = HandTool::for_scene(&mut built, camera.yaw).unwrap();
    // Pictures for the report when an offscreen renderer exists (lavapipe will do).
    let pictures = Screenshots::new(
        None,
        &built.solver,
        &built.skin,
        ImageSize(480, 270),
        Default::default(),
    )
    .map(|s| s.with_tool(&hand.tool).with_decal(mode.decal.clone()))
    .map_err(|e| format!("{e:#}"));
    let rendered = pictures.is_ok();
    let mut body = Body::Cpu(Box::new(built.solver));
    let dt = body.solver().params().frame_dt as f64;

    // The exercise's reference stroke moves the blade, as "Watch the reference" does.
    let reference = mode.reference().unwrap();
    let frames = ((reference.end_time() + 0.2) / dt).ceil() as u64;
    hand.play(reference);
    mode.start(&mut hand, &mut body, pictures).unwrap();
    assert_eq!(mode.running(), Some(0));
    for _ in 0..frames {
        hand.before_step(&mut body).unwrap();
        let stats = body.step_frame().unwrap();
        hand.after_step(&stats);
        mode.after_step(incise::exercise::ToolFrame::of_xpbd(&stats));
    }
    assert_eq!(mode.running(), Some(frames as usize));
    let live_released: Vec<u64> = (0..body.solver().mesh().tet_count())
        .filter(|&t| !body.solver().cut().is_live(t))
        .map(|t| t as u64)
        .collect();
    let out_root = dir.join("out/exercises");
    let done = mode.finish(&mut hand, &body, &out_root, &history).unwrap();
    assert_eq!(mode.running(), None);
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
    // A second finish has nothing to finish.
    assert!(mode.finish(&mut hand, &body, &out_root, &history).is_err());

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

/// The method window's attempt on the Nakao plate exercise, without a window: the
/// reference stroke moves the mouse blade (engaged), the attempt records its pose each
/// frame and is scored on the body's cut surface; `incise exercise` on the recorded
/// stroke.ron cuts the same surface and gives the same score.
#[test]
fn a_method_window_attempt_on_a_nakao_exercise_scores_as_incise_exercise_does() {
    use incise::preview::method_exercise::MethodExercise;
    use incise::sim_body::ToolInput;
    use incise::sim_body::recorded::RecordedBody;
    const NAKAO: &str = "config/exercises/plate_line_nakao.ron";
    let dir = temp_dir("preview-exercise-nakao");
    let history = dir.join("history.jsonl");
    let mut mode = MethodExercise::open(Path::new(NAKAO)).unwrap();
    let mut body = RecordedBody::open(mode.live.scene_path()).unwrap();
    let reference = mode.live.reference().unwrap();
    let dt = body.body.frame_dt();
    let frames = (reference.end_time() / dt).ceil() as u64;
    mode.start(&mut body).unwrap();
    assert!(!mode.live.touched());
    for f in 1..=frames {
        let pose = reference.pose_at(f as f64 * dt);
        body.step(&ToolInput::Hand {
            pose,
            engaged: true,
        })
        .unwrap();
        mode.after_step(&body, pose, true).unwrap();
    }
    assert!(mode.live.touched(), "the blade never touched the plate");
    assert_eq!(mode.live.running(), Some(frames as usize));
    let done = mode
        .finish(&body, &dir.join("out/exercises"), &history)
        .unwrap();
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
