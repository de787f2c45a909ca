//! A budgeted Nakao scene replays bit for bit when its localisation is replayed: the
//! refresh-rate manager of `config/chest_incision_nakao.ron` (`Budget(5.6)`) picks each
//! frame's free nodes from wall time, so two runs part within a few frames; a run given
//! the first run's free-node counts (`OpenOptions::free_nodes`, what `incise soak` replays)
//! leaves the same model, every bit (`Outcome::hash`), after every frame.

use std::path::Path;

use incise::report::FrameData;
use incise::scene::load_scene;
use incise::sim_body::{DeviceChoice, OpenOptions, ToolInput, open};

/// One frame of a run: the localisation level, the free nodes and the model's state hash.
type Frame = (Option<u32>, usize, u64);

/// Every frame of the chest scene's script, its free nodes replayed from `free` if given.
fn run(free: Option<Vec<usize>>) -> Vec<Frame> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/chest_incision_nakao.ron");
    let scene = load_scene(&path).unwrap();
    let opts = OpenOptions {
        device: DeviceChoice::Cpu,
        quiet: true,
        free_nodes: free,
        ..OpenOptions::default()
    };
    let mut body = open(&scene, &path, &opts).unwrap().0;
    let frames = (scene.duration as f64 / body.frame_dt()).round() as usize;
    (0..frames)
        .map(|f| match body.step(&ToolInput::Script).unwrap() {
            FrameData::Edges(s) => (s.level, s.free_nodes.unwrap(), body.outcome().unwrap().hash),
            FrameData::Xpbd(_) => panic!("frame {f}: the chest scene is a Nakao scene"),
        })
        .collect()
}

/// The first frame where `b` differs from `a`, both frames, for the failure message.
fn first_difference(a: &[Frame], b: &[Frame]) -> Option<(usize, Frame, Frame)> {
    a.iter()
        .zip(b)
        .position(|(x, y)| x != y)
        .map(|k| (k, a[k], b[k]))
}

#[test]
fn the_budgeted_chest_replays_bit_for_bit_with_the_first_runs_free_nodes() {
    let first = run(None);
    let free: Vec<usize> = first
        .iter()
        .filter(|f| f.0.is_some())
        .map(|f| f.1)
        .collect();
    // The manager localises every frame (the blade is posed from the first) and moves the
    // free set: a replay of a constant level would test nothing.
    assert_eq!(free.len(), first.len());
    assert!(free.iter().min() < free.iter().max(), "{free:?}");
    let replays = [run(Some(free.clone())), run(Some(free))];
    for (k, replay) in replays.iter().enumerate() {
        assert_eq!(replay.len(), first.len());
        assert_eq!(
            first_difference(&first, replay),
            None,
            "replay {k} (frame, (level, free nodes, hash) first, replay)"
        );
    }
}
