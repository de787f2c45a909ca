//! Scenes anywhere (issue 34 item 2): the shipped config/ tree is built into the binary,
//! so a shipped scene or exercise runs by name, or by its `config/…` path, from any
//! directory (an installed binary has no clone beside it); `incise scenes` lists them and
//! `incise scenes export DIR` writes the tree out to edit.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{temp_dir, text};
use incise::scene::built_in;

/// Every `.ron` file under `dir`, as paths relative to it.
fn ron_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "ron") {
                out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// `incise ARGS` run in `cwd` (outside the clone), its cache in `cache`.
fn incise_in(cwd: &Path, cache: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_incise"))
        .args(args)
        .current_dir(cwd)
        .env("XDG_CACHE_HOME", cache)
        .output()
        .expect("incise runs")
}

#[test]
fn the_built_in_tree_is_the_config_folder() {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    let on_disk = ron_files(&config);
    let mut built: Vec<PathBuf> = built_in::FILES.iter().map(|(p, _)| p.into()).collect();
    built.sort();
    assert_eq!(
        built, on_disk,
        "src/scene/built_in.rs FILES must list config/"
    );
    for (path, text) in built_in::FILES {
        let disk = std::fs::read_to_string(config.join(path)).unwrap();
        assert_eq!(*text, disk, "{path}");
    }
}

#[test]
fn shipped_scenes_run_by_name_and_by_config_path_from_any_directory() {
    let dir = temp_dir("built-in-scenes");
    let cache = dir.join("cache");
    let list = incise_in(&dir, &cache, &["scenes"]);
    assert!(list.status.success(), "{}", text(&list.stderr));
    let listed = text(&list.stdout);
    for name in ["intestine_pull ", "plate_cut ", "exercises/slab_depth "] {
        assert!(listed.contains(name), "{name} not listed:\n{listed}");
    }
    assert!(
        !listed.contains("materials"),
        "presets are not scenes:\n{listed}"
    );

    for scene in ["plate_cut", "config/plate_cut.ron"] {
        let out = dir.join("out");
        let o = incise_in(
            &dir,
            &cache,
            &["run", scene, "--frames", "2", "--vtu-every", "0", "--quiet"],
        );
        assert!(o.status.success(), "{scene}: {}", text(&o.stderr));
        assert!(text(&o.stdout).contains("completed 2 frames of plate_cut"));
        assert!(text(&o.stderr).contains("is the built-in plate_cut.ron"));
        let _ = std::fs::remove_dir_all(out);
    }

    // An exercise by its config path: its `scene: "../slab_layer.ron"` and the reference
    // stroke resolve inside the built-in tree.
    let o = incise_in(
        &dir,
        &cache,
        &[
            "exercise",
            "config/exercises/slab_depth.ron",
            "--stroke",
            "config/strokes/slab_depth_reference.ron",
            "--out",
            "attempt",
            "--history",
            "history.jsonl",
            "--quiet",
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(dir.join("attempt/result.json").is_file());

    // The headset on a built-in scene and a built-in headset script, both by name: every
    // command's file arguments resolve the same way.
    let o = incise_in(
        &dir,
        &cache,
        &[
            "xr",
            "plate_cut",
            "--simulated-headset",
            "xr/plate_cut_headset",
            "--frames",
            "3",
            "--out",
            "xr_out",
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(dir.join("xr_out/xr_report.json").is_file());

    // A name that is neither a file nor built in fails naming it, once.
    let o = incise_in(&dir, &cache, &["run", "no_such_scene", "--frames", "1"]);
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert_eq!(err.matches("no_such_scene").count(), 1, "{err}");
}

#[test]
fn scenes_export_writes_the_tree_to_edit() {
    let dir = temp_dir("built-in-export");
    let o = incise_in(&dir, &dir.join("cache"), &["scenes", "export", "mine"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    assert_eq!(ron_files(&dir.join("mine")), ron_files(&config));
    let a = std::fs::read(dir.join("mine/tools/scalpel_10.ron")).unwrap();
    assert_eq!(
        a,
        std::fs::read(config.join("tools/scalpel_10.ron")).unwrap()
    );
}
