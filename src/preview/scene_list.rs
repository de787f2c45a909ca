//! The scene and exercise files the preview's panel offers: the `.ron` files of a
//! folder that are scenes or exercises, not presets files.

use std::path::{Path, PathBuf};

/// `.ron` files in `dir` that are not presets files (scenes, or exercises in theirs),
/// sorted.
pub fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron") && !is_presets(p))
        .collect();
    v.sort();
    v
}

/// Whether the RON file `path` is a presets file (`materials.ron`, rheology presets): a
/// map of named entries, where a scene or an exercise is a struct `( .. )`.
fn is_presets(path: &Path) -> bool {
    std::fs::read_to_string(path).is_ok_and(|text| {
        ron::from_str::<std::collections::BTreeMap<String, ron::Value>>(&text).is_ok()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// config/ offers its scenes but not its two presets files (materials, rheology), and
    /// a copy of a presets file under another name is known by its content.
    #[test]
    fn the_scene_list_leaves_out_presets_files() {
        let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
        let names = |dir: &Path| -> Vec<String> {
            scene_files(dir)
                .iter()
                .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                .collect()
        };
        let listed = names(&config);
        for scene in ["plate_cut.ron", "plate_cut_nakao.ron", "organ_layers.ron"] {
            assert!(listed.contains(&scene.to_string()), "{scene}: {listed:?}");
        }
        for presets in ["materials.ron", "rheology.ron"] {
            assert!(
                !listed.contains(&presets.to_string()),
                "{presets}: {listed:?}"
            );
        }
        let dir = std::env::temp_dir().join(format!("incise-scene-list-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(config.join("rheology.ron"), dir.join("soft.ron")).unwrap();
        std::fs::copy(config.join("plate_cut.ron"), dir.join("cut.ron")).unwrap();
        assert_eq!(names(&dir), ["cut.ron"]);
        assert_eq!(names(&config.join("exercises")).len(), 4);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
