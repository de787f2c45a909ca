//! Issue 18: the scene figures docs/performance.md quotes come from a command (`incise
//! experiment scene-figures --update docs/performance.md`) and still match what the
//! scenes produce: each row is rerun and compared (frames and tets exactly, released
//! tets within 3 %, peak tool force within 10 %). After an intended physics change,
//! regenerate the table with that command.

use std::path::Path;

use incise::experiment::scene_figures::{markdown, measure, parse};

#[test]
fn quoted_scene_figures_match_the_scenes_now() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/performance.md")).unwrap();
    let quoted = parse(&doc).unwrap();
    assert!(
        !quoted.is_empty(),
        "docs/performance.md quotes no scene figures"
    );
    let regenerate =
        "regenerate with `incise experiment scene-figures --update docs/performance.md`";
    for q in &quoted {
        let now = measure(&root.join(&q.scene)).unwrap();
        let off = |a: f64, b: f64, rel: f64| (a - b).abs() > rel * b.abs().max(1e-9);
        assert!(
            now.frames == q.frames
                && now.tets == q.tets
                && !off(now.released as f64, q.released as f64, 0.03)
                && !off(now.peak_force, q.peak_force, 0.10),
            "docs/performance.md quotes {q:?}, the scene gives {now:?}: {regenerate}"
        );
    }
    // The table round-trips through its generator.
    assert_eq!(parse(&markdown(&quoted)).unwrap(), quoted);
}
