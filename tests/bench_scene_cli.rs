//! Issue 20, item 2: `incise bench scene` times any method's frames through its body: the
//! Nakao chest (with the refresh-rate manager's levels and the loop split) and the layered
//! organ (rheology, no localisation), as text and as JSON. No wall-time assertions: the
//! figures are checked for what they are (counts, frames, ordered ranges).

mod common;

use common::{incise, text};

/// `incise bench scene` of `scene`, `frames` frames, with `extra` flags; stdout.
fn bench(scene: &str, frames: &str, extra: &[&str]) -> String {
    let args = [
        &["bench", "scene", "--scene", scene, "--frames", frames][..],
        extra,
    ]
    .concat();
    let o = incise(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    text(&o.stdout)
}

#[test]
fn the_nakao_chest_prints_its_method_counts_levels_and_loop_split() {
    // The blade starts at 0.1 s: frames 10-14 cut, under the 5.6 ms budget's manager.
    let out = bench("config/chest_incision_nakao.ron", "15", &[]);
    let mut lines = out.lines();
    let head = lines.next().unwrap();
    assert!(
        head.starts_with("config/chest_incision_nakao.ron (nakao on cpu (mass-spring)): ")
            && head.contains("17582 nodes, 73536 tets; 15 frames: ")
            && head.contains(" ms/frame min, "),
        "{out}"
    );
    let loc = lines
        .next()
        .unwrap_or_else(|| panic!("no localisation line: {out}"));
    let levels = loc
        .split("levels ")
        .nth(1)
        .and_then(|l| l.split(',').next())
        .unwrap_or_else(|| panic!("no level range: {out}"));
    let (lo, hi) = levels.split_once('–').unwrap();
    let (lo, hi): (u32, u32) = (lo.parse().unwrap(), hi.parse().unwrap());
    assert!(lo >= 1 && lo <= hi, "{loc}");
    for part in [
        "localisation budget 5.6 ms",
        "localise ",
        "force ",
        "integrate ",
        "cut ",
    ] {
        assert!(loc.contains(part), "{part}: {loc}");
    }
}

#[test]
fn the_layered_organ_prints_the_rheology_figures_as_text_and_json() {
    let out = bench("config/organ_layers.ron", "3", &[]);
    assert!(
        out.starts_with(
            "config/organ_layers.ron (rheology on cpu (rheology)): 196 nodes, 648 tets; 3 frames: "
        ) && out.lines().count() == 1,
        "{out}"
    );
    let r: serde_json::Value =
        serde_json::from_str(&bench("config/organ_layers.ron", "3", &["--json"])).unwrap();
    assert_eq!(
        (
            r["method"].as_str(),
            r["nodes"].as_u64(),
            r["frames"].as_u64()
        ),
        (Some("rheology"), Some(196), Some(3)),
        "{r}"
    );
    let (min, median, p99) = (
        r["frame_ms_min"].as_f64().unwrap(),
        r["frame_ms_median"].as_f64().unwrap(),
        r["frame_ms_p99"].as_f64().unwrap(),
    );
    assert!(0.0 < min && min <= median && median <= p99, "{r}");
    assert!(r.get("localisation").is_none(), "{r}");
}
