//! Where scripts/monado.sh gets Monado (issue 34 item 4): the tarball beside the project
//! when it is there, else upstream's git repository at the full pinned commit. A clone
//! alone on a machine that cannot reach upstream gets one message naming both fixes, and a
//! repository that does not hold the pinned commit is refused, never built.
//!
//! Runs the script with an empty source folder, a scratch cache and `INCISE_MONADO_GIT`
//! pointed at a repository that cannot serve the commit, so nothing is built and nothing
//! leaves the machine (the script's package check runs first, as it does for the XR
//! tests).

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{temp_dir, text};

/// The pinned commit, as scripts/monado.sh and ../shared/monado/README.md name it.
const COMMIT: &str = "3b0f9380286f13d193d98ed505b02a09e5220c0a";

/// `bash scripts/monado.sh` with no tarball in `dir/src`, its cache in `dir/cache` and
/// `git` as Monado's repository.
fn monado_sh(dir: &Path, git: &str) -> Output {
    let src = dir.join("src");
    std::fs::create_dir_all(&src).unwrap();
    Command::new("bash")
        .arg("scripts/monado.sh")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("INCISE_MONADO_SRC", &src)
        .env("INCISE_MONADO_CACHE", dir.join("cache"))
        .env("INCISE_MONADO_GIT", git)
        .output()
        .expect("bash runs")
}

/// The script's own lines (`monado.sh: …`) of `o`'s stderr.
fn said(o: &Output) -> String {
    text(&o.stderr)
        .lines()
        .filter(|l| l.starts_with("monado.sh:"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn without_the_tarball_or_upstream_the_script_names_both_fixes() {
    let dir = temp_dir("monado-offline");
    let o = monado_sh(&dir, "/nonexistent/monado.git");
    assert!(!o.status.success(), "{}", text(&o.stderr));
    assert!(o.stdout.is_empty(), "no manifest path: {}", text(&o.stdout));
    let msg = said(&o);
    for needed in [
        "monado-3b0f9380286f.tar.gz is missing",
        COMMIT,
        "INCISE_MONADO_SRC",
        "INCISE_MONADO_GIT",
        "offline",
    ] {
        assert!(msg.contains(needed), "missing {needed:?} in: {msg}");
    }
    assert!(
        !dir.join("cache/monado").exists(),
        "the failed fetch is cleaned up"
    );
}

#[test]
fn a_repository_without_the_pinned_commit_is_refused() {
    let dir = temp_dir("monado-wrong-repo");
    let repo = dir.join("other");
    let git = |args: &[&str]| {
        let o = Command::new("git")
            .args(args)
            .current_dir(&repo)
            .output()
            .unwrap();
        assert!(o.status.success(), "git {args:?}: {}", text(&o.stderr));
    };
    std::fs::create_dir_all(&repo).unwrap();
    git(&["init", "-q"]);
    std::fs::write(repo.join("README"), "not Monado").unwrap();
    git(&["add", "README"]);
    git(&[
        "-c",
        "user.name=t",
        "-c",
        "user.email=t@t",
        "commit",
        "-qm",
        "not Monado",
    ]);
    let o = monado_sh(&dir, repo.to_str().unwrap());
    assert!(!o.status.success(), "{}", text(&o.stderr));
    let msg = said(&o);
    assert!(
        msg.contains(&format!("does not hold the pinned commit {COMMIT}")),
        "{msg}"
    );
    assert!(!dir.join("cache/build").exists(), "nothing was built");
}
