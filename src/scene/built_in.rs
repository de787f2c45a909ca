//! The shipped `config/` tree built into the binary (issue 34 item 2): a scene copied out
//! of config/ (or any scene whose folder has no preset file of that name) still finds the
//! shipped material and rheology presets, a file beside the scene winning over the built-in
//! copy; and a shipped scene, exercise or headset script runs by name (`incise run
//! intestine_pull`) or by its `config/…` path from any directory, from a copy of the tree
//! exported once to the user's cache folder (`incise scenes export DIR` writes it anywhere).

use std::path::{Path, PathBuf};

use incise_sim::ron_file::{self, ReadError};

/// Every file of the shipped `config/` tree: (path under config/, text). A test keeps the
/// list equal to the folder.
pub const FILES: &[(&str, &str)] = &[
    ("beam_sag.ron", include_str!("../../config/beam_sag.ron")),
    (
        "bowel_cantilever.ron",
        include_str!("../../config/bowel_cantilever.ron"),
    ),
    (
        "chest_incision_nakao.ron",
        include_str!("../../config/chest_incision_nakao.ron"),
    ),
    (
        "exercises/intestine_enterotomy.ron",
        include_str!("../../config/exercises/intestine_enterotomy.ron"),
    ),
    (
        "exercises/plate_line_nakao.ron",
        include_str!("../../config/exercises/plate_line_nakao.ron"),
    ),
    (
        "exercises/slab_arc.ron",
        include_str!("../../config/exercises/slab_arc.ron"),
    ),
    (
        "exercises/slab_depth.ron",
        include_str!("../../config/exercises/slab_depth.ron"),
    ),
    (
        "intestine_enterotomy.ron",
        include_str!("../../config/intestine_enterotomy.ron"),
    ),
    (
        "intestine_incision.ron",
        include_str!("../../config/intestine_incision.ron"),
    ),
    (
        "intestine_pull.ron",
        include_str!("../../config/intestine_pull.ron"),
    ),
    (
        "intestine_pull_xpbd.ron",
        include_str!("../../config/intestine_pull_xpbd.ron"),
    ),
    ("materials.ron", include_str!("../../config/materials.ron")),
    (
        "organ_layers.ron",
        include_str!("../../config/organ_layers.ron"),
    ),
    ("plate_cut.ron", include_str!("../../config/plate_cut.ron")),
    (
        "plate_cut_nakao.ron",
        include_str!("../../config/plate_cut_nakao.ron"),
    ),
    (
        "plate_stretch.ron",
        include_str!("../../config/plate_stretch.ron"),
    ),
    ("rheology.ron", include_str!("../../config/rheology.ron")),
    (
        "slab_layer.ron",
        include_str!("../../config/slab_layer.ron"),
    ),
    (
        "strokes/intestine_enterotomy_reference.ron",
        include_str!("../../config/strokes/intestine_enterotomy_reference.ron"),
    ),
    (
        "strokes/plate_line_nakao_reference.ron",
        include_str!("../../config/strokes/plate_line_nakao_reference.ron"),
    ),
    (
        "strokes/slab_arc_reference.ron",
        include_str!("../../config/strokes/slab_arc_reference.ron"),
    ),
    (
        "strokes/slab_depth_reference.ron",
        include_str!("../../config/strokes/slab_depth_reference.ron"),
    ),
    (
        "tools/scalpel_10.ron",
        include_str!("../../config/tools/scalpel_10.ron"),
    ),
    (
        "tools/scalpel_11.ron",
        include_str!("../../config/tools/scalpel_11.ron"),
    ),
    (
        "xr/plate_cut_headset.ron",
        include_str!("../../config/xr/plate_cut_headset.ron"),
    ),
];

/// The text of the file `name` (relative to a scene's folder `dir`: a preset file, a
/// tool, a stroke) and the path that names it in errors and reports: the file there when
/// there is one, else the built-in copy of the shipped `config/NAME` (`built-in
/// config/NAME`), else the read error of the file there.
pub fn config_text(dir: &Path, name: &str) -> Result<(PathBuf, String), ReadError> {
    let beside = dir.join(name);
    if beside.exists() {
        return Ok((beside.clone(), ron_file::read(&beside)?));
    }
    match FILES.iter().find(|(shipped, _)| *shipped == name) {
        Some((shipped, text)) => Ok((
            PathBuf::from(format!("built-in config/{shipped}")),
            text.to_string(),
        )),
        None => Err(ron_file::read(&beside).expect_err("the file does not exist")),
    }
}

/// The built-in scenes and exercises: (name, path under config/, first comment line), in
/// file order; presets, tools, strokes and headset scripts are not scenes.
pub fn scenes() -> Vec<(String, &'static str, String)> {
    FILES
        .iter()
        .filter(|(path, _)| {
            let top = !path.contains('/') || path.starts_with("exercises/");
            top && !matches!(*path, "materials.ron" | "rheology.ron")
        })
        .map(|(path, text)| {
            let name = path.trim_end_matches(".ron").to_string();
            let about = text
                .lines()
                .find_map(|l| l.trim().strip_prefix("//"))
                .unwrap_or("")
                .trim()
                .to_string();
            (name, *path, about)
        })
        .collect()
}

/// Write the built-in tree into `dir` (`dir/intestine_pull.ron`, `dir/tools/…`), over
/// files of the same names; returns how many files were written.
pub fn export(dir: &Path) -> std::io::Result<usize> {
    for (path, text) in FILES {
        let to = dir.join(path);
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(&to, text)?;
    }
    Ok(FILES.len())
}

/// The file `arg` names: itself when it exists; else a built-in one — a bare name
/// (`intestine_pull`, `intestine_pull.ron`, `exercises/slab_depth`) or a `config/…` path
/// of the shipped tree (the default scenes, the README's commands) — from the tree exported
/// to the cache folder (once per build of incise); else `arg` unchanged (its read then
/// fails naming it).
pub fn resolve(arg: &Path) -> PathBuf {
    if arg.exists() {
        return arg.to_path_buf();
    }
    let Some(rel) = built_in_path(arg) else {
        return arg.to_path_buf();
    };
    let dir = cache_dir();
    let exported = dir.join(rel);
    if exported.exists() || export(&dir).is_ok() {
        eprintln!(
            "note: {} is the built-in {rel} (from {})",
            arg.display(),
            dir.display()
        );
        return exported;
    }
    arg.to_path_buf()
}

/// The path under config/ of the built-in file `arg` names, if it names one.
fn built_in_path(arg: &Path) -> Option<&'static str> {
    let text = arg.to_str()?.replace('\\', "/");
    let rel = text.strip_prefix("config/").unwrap_or(&text);
    let with_ext = if rel.ends_with(".ron") {
        rel.to_string()
    } else {
        format!("{rel}.ron")
    };
    FILES
        .iter()
        .map(|(path, _)| *path)
        .find(|path| *path == with_ext)
}

/// Where the built-in tree is exported: the user's cache folder (`$XDG_CACHE_HOME`,
/// `%LOCALAPPDATA%` on Windows, `~/.cache`, else the temp folder), one folder per content
/// of the tree (so a newer incise never reads an older export).
fn cache_dir() -> PathBuf {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    FILES.hash(&mut h);
    let var = |v: &str| {
        std::env::var_os(v)
            .filter(|s| !s.is_empty())
            .map(PathBuf::from)
    };
    let base = var("XDG_CACHE_HOME")
        .or_else(|| var("LOCALAPPDATA"))
        .or_else(|| var("HOME").map(|h| h.join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("incise")
        .join(format!("config-{:016x}", h.finish()))
}
