//! The preset files built into the binary: a scene copied out of config/ (or any scene whose
//! folder has no preset file of that name) still finds the shipped material and rheology
//! presets. A file beside the scene wins over the built-in copy.

use std::path::{Path, PathBuf};

use incise_sim::ron_file::{self, ReadError};

/// The shipped `config/materials.ron`.
pub const MATERIALS: &str = include_str!("../../config/materials.ron");

/// The shipped `config/rheology.ron`.
pub const RHEOLOGY: &str = include_str!("../../config/rheology.ron");

/// The text of the preset file `name` of a scene in `dir`, and the path that names it in
/// errors and reports: the file beside the scene when there is one, else the built-in copy
/// of a shipped preset file (`built-in config/NAME`), else the read error of the file
/// beside the scene.
pub fn preset_text(dir: &Path, name: &str) -> Result<(PathBuf, String), ReadError> {
    let beside = dir.join(name);
    if beside.exists() {
        return Ok((beside.clone(), ron_file::read(&beside)?));
    }
    let built_in = match name {
        "materials.ron" => MATERIALS,
        "rheology.ron" => RHEOLOGY,
        _ => return Err(ron_file::read(&beside).expect_err("the file does not exist")),
    };
    Ok((
        PathBuf::from(format!("built-in config/{name}")),
        built_in.to_string(),
    ))
}
