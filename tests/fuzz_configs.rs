//! Issue 11: the RON parsers of scenes, tools, strokes, exercises and headset scripts
//! survive mutation fuzzing seeded with the shipped files (≥ 100k inputs per format by default, `INCISE_FUZZ_INPUTS` to
//! change): no panic, no input slower than 1 s, never more than 10× the input allocated;
//! each format's mutants are both accepted and rejected (the mutator reaches past the
//! parser's first check). Issue 33 item 4: the committed regression corpus
//! (`tests/fuzz/configs/<format>/`, README there) is rejected the same way, without a panic.

#[path = "../crates/sim/tests/fuzz/mutator.rs"]
mod mutator;

use std::path::Path;
use std::time::Instant;

use mutator::{alloc_meter::Meter, fuzz, inputs_per_format};

#[global_allocator]
static METER: Meter = Meter;

/// Fixed-size allocations (error strings, the parser's own tables).
const SLACK: usize = 256 * 1024;

/// The `.ron` files directly in `dir` (under the workspace), sorted: (path, bytes).
fn ron_files(dir: &Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out: Vec<_> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()))
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "ron").then(|| (p.clone(), std::fs::read(&p).unwrap()))
        })
        .collect();
    out.sort();
    out
}

/// The seed texts in `dir`.
fn files(dir: &str) -> Vec<Vec<u8>> {
    ron_files(Path::new(dir))
        .into_iter()
        .map(|(_, b)| b)
        .collect()
}

fn stroke_seed() -> Vec<u8> {
    b"(\n    poses: [\n        (t: 0.0, position: (0.0, 0.0, 0.03), rotation: (0.0, 0.0, 0.0, 1.0)),\n        (t: 0.5, position: (0.01, 0.0, 0.02), rotation: (0.0, 0.0, 0.38268343, 0.9238795)),\n        (t: 1.0, position: (0.04, 0.0, 0.02), rotation: (0.0, 0.0, 0.0, 1.0)),\n    ],\n)\n"
        .to_vec()
}

/// A parser under test: true if it accepted the text.
type Parser = fn(&str, &Path) -> bool;

/// Each format: its name (the corpus folder under `tests/fuzz/configs/`), seed files and
/// parser.
fn formats() -> [(&'static str, Vec<Vec<u8>>, Parser); 5] {
    [
        ("scene", files("config"), |t, p| {
            incise::scene::parse_scene(t, p).is_ok()
        }),
        ("tool", files("config/tools"), |t, p| {
            incise_scalpel::parse_tool(t, p).is_ok()
        }),
        ("stroke", vec![stroke_seed()], |t, p| {
            incise_scalpel::parse_stroke(t, p).is_ok()
        }),
        ("exercise", files("config/exercises"), |t, p| {
            incise::exercise::parse_exercise(t, p).is_ok()
        }),
        ("headset", files("config/xr"), |t, p| {
            incise_xr::simulated::HeadsetScript::parse(t, p).is_ok()
        }),
    ]
}

#[test]
fn mutated_configs_never_panic_hang_or_overallocate() {
    let count = inputs_per_format();
    let path = Path::new("fuzz.ron");
    for (k, (name, seeds, parse)) in formats().into_iter().enumerate() {
        assert!(!seeds.is_empty(), "{name}: no seed files");
        let t = Instant::now();
        let (ok, bad, slowest) = fuzz(name, &seeds, count, 0xC0FF_EE00 + k as u64, SLACK, |b| {
            std::str::from_utf8(b).is_ok_and(|text| parse(text, path))
        });
        println!(
            "{name}: {count} inputs in {:.1} s — {ok} accepted, {bad} rejected, slowest {slowest:?}",
            t.elapsed().as_secs_f64()
        );
        assert!(
            ok > 0 && bad > 0,
            "{name}: the mutants should be both accepted ({ok}) and rejected ({bad})"
        );
    }
}

#[test]
fn the_regression_corpus_is_rejected_without_a_panic() {
    let path = Path::new("corpus.ron");
    for (name, _, parse) in formats() {
        let cases = ron_files(&Path::new("tests/fuzz/configs").join(name));
        assert!(!cases.is_empty(), "{name}: no regression inputs");
        for (file, bytes) in cases {
            let t = Instant::now();
            let accepted = std::panic::catch_unwind(|| {
                mutator::alloc_meter::peak_during(|| {
                    std::str::from_utf8(&bytes).is_ok_and(|text| parse(text, path))
                })
            });
            let (accepted, bytes_used) =
                accepted.unwrap_or_else(|_| panic!("{} panics", file.display()));
            assert!(!accepted, "{} is accepted", file.display());
            assert!(
                bytes_used <= 10 * bytes.len() + SLACK,
                "{} allocated {bytes_used} bytes",
                file.display()
            );
            assert!(
                t.elapsed().as_secs_f64() < 1.0,
                "{} is slow",
                file.display()
            );
        }
    }
}
