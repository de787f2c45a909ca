//! A scene's tissue material: its own values, or a preset of `materials.ron` beside the
//! scene file (the built-in copy of the shipped one where there is none).

use std::path::Path;

use anyhow::{Result, anyhow};
use incise_sim::Material;

use super::built_in::config_text;
use super::{MaterialChoice, Scene, parse_materials};

/// The material of `scene` (read from `scene_path`) and its name ("custom" for values
/// given in the scene); an error naming the file when it is missing or an unknown preset.
pub fn scene_material(scene: &Scene, scene_path: &Path) -> Result<(Material, String)> {
    let dir = scene_path.parent().unwrap_or(Path::new("."));
    Ok(match &scene.material {
        MaterialChoice::Unset => {
            return Err(anyhow!("{}: material is missing", scene_path.display()));
        }
        MaterialChoice::Custom(m) => (*m, "custom".to_string()),
        MaterialChoice::Preset(name) => {
            let (file, text) = config_text(dir, "materials.ron")?;
            let presets = parse_materials(&text, &file)?;
            let m = presets.get(name).ok_or_else(|| {
                anyhow!(
                    "{}: material preset \"{name}\" is not in {} (known: {})",
                    scene_path.display(),
                    file.display(),
                    presets.keys().cloned().collect::<Vec<_>>().join(", ")
                )
            })?;
            (*m, name.clone())
        }
    })
}
