//! Reading scene and material files, with errors that name file, line, column and field.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use incise_sim::Material;
use incise_sim::ron_file::{self, ReadError, SyntaxError};

use super::{MaterialChoice, Method, Scene};

/// Why a scene or material file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error(transparent)]
    Io(#[from] ReadError),
    /// RON syntax, unknown field, wrong type: ron's position and message.
    #[error(transparent)]
    Syntax(#[from] SyntaxError),
    /// A value parsed but is out of range.
    #[error("{path}:{line}: {field} {msg}")]
    Value {
        /// The file.
        path: PathBuf,
        /// 1-based line of the field (0 if not found in the text).
        line: usize,
        /// Dotted field path.
        field: String,
        /// What is wrong.
        msg: String,
    },
}

/// Read and validate a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = ron_file::read(path)?;
    parse_scene(&text, path)
}

/// Parse and validate scene text; `path` names it in errors.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let mut scene: Scene = ron_file::parse(text, path)?;
    super::default_scheme::apply(&mut scene, text, path)?;
    let value_err = |field: &str, msg: String| SceneError::Value {
        path: path.into(),
        line: locate(text, field),
        field: field.to_string(),
        msg,
    };
    if !(scene.duration.is_finite() && scene.duration > 0.0) {
        return Err(value_err(
            "duration",
            format!(
                "must be a positive number of seconds, got {}",
                scene.duration
            ),
        ));
    }
    if let Err(incise_sim::xpbd::SolverError::BadParameter { field, msg }) = scene.solver.validate()
    {
        return Err(value_err(&format!("solver.{field}"), msg));
    }
    if let MaterialChoice::Custom(m) = &scene.material {
        m.validate()
            .map_err(|e| value_err("material", e.to_string()))?;
    }
    if let Some(c) = &scene.cutting {
        if !(c.von_mises_threshold.is_finite() && c.von_mises_threshold > 0.0) {
            return Err(value_err(
                "cutting.von_mises_threshold",
                format!(
                    "must be a positive stress in Pa, got {}",
                    c.von_mises_threshold
                ),
            ));
        }
    }
    let scheme = scene.solver.scheme;
    if scheme != incise_sim::implicit::Scheme::Xpbd && scene.model.method() != Method::Xpbd {
        return Err(value_err(
            "solver.scheme",
            format!(
                "is {}, a scheme of the Xpbd model's tet solver; a {} scene steps its own \
                 way: remove this field",
                scheme.name(),
                scene.model.method().name()
            ),
        ));
    }
    match (&scene.model, &scene.material) {
        (super::ModelChoice::Rheology(rh), material) => {
            if !matches!(material, MaterialChoice::Unset) {
                return Err(value_err(
                    "material",
                    "is not used by a Rheology model: its presets are named in \
                     model.material and model.regions; remove this field"
                        .into(),
                ));
            }
            rh.validate()
                .map_err(|(field, msg)| value_err(&field, msg))?;
        }
        (_, MaterialChoice::Unset) => {
            return Err(value_err(
                "material",
                "is missing: Xpbd and MassSpring scenes need Preset(\"name\") or \
                 Custom((youngs_modulus: …, poisson_ratio: …, density: …))"
                    .into(),
            ));
        }
        (super::ModelChoice::MassSpring(ms), _) => {
            ms.validate()
                .map_err(|(field, msg)| value_err(&field, msg))?;
        }
        (super::ModelChoice::Xpbd, _) => {}
    }
    for (i, g) in scene.grabs.iter().enumerate() {
        if !(g.speed.is_finite() && g.speed > 0.0) {
            return Err(value_err(
                &format!("grabs[{i}].speed"),
                format!("must be a positive speed in m/s, got {}", g.speed),
            ));
        }
        if g.path.is_empty() || g.path.iter().any(|p| !p.is_finite()) {
            return Err(value_err(
                &format!("grabs[{i}].path"),
                "must list at least one finite waypoint".into(),
            ));
        }
        if !(g.start.is_finite() && g.start >= 0.0) {
            return Err(value_err(
                &format!("grabs[{i}].start"),
                format!("must be >= 0 s, got {}", g.start),
            ));
        }
    }
    Ok(scene)
}

/// Read `materials.ron`: a map from preset name to material, each validated.
pub fn load_materials(path: &Path) -> Result<BTreeMap<String, Material>, SceneError> {
    parse_materials(&ron_file::read(path)?, path)
}

/// Parse the text of a `materials.ron` (`path` names it in errors), each material
/// validated.
pub fn parse_materials(text: &str, path: &Path) -> Result<BTreeMap<String, Material>, SceneError> {
    let map: BTreeMap<String, Material> = ron_file::parse(text, path)?;
    for (name, m) in &map {
        m.validate().map_err(|e| SceneError::Value {
            path: path.into(),
            line: field_line(text, &format!("\"{name}\"")),
            field: name.clone(),
            msg: e.to_string(),
        })?;
    }
    Ok(map)
}

/// 1-based line of the dotted `field` in scene text (0 when not found): the first line of
/// its last name, except inside `model.regions[i]`, where it is looked for from the i-th
/// region on (each region has one `tets:` line).
pub fn locate(text: &str, field: &str) -> usize {
    let last = field.rsplit('.').next().unwrap_or(field);
    let Some(rest) = field.strip_prefix("model.regions[") else {
        return field_line(text, last);
    };
    let Some(index) = rest.split(']').next().and_then(|i| i.parse::<usize>().ok()) else {
        return field_line(text, last);
    };
    let start = field_line(text, "regions");
    if start == 0 {
        return 0;
    }
    let after: String = text.lines().skip(start - 1).collect::<Vec<_>>().join("\n");
    // Line (within `after`) of the region's `tets:`, then of the field from there on.
    let mut offset = 0;
    for _ in 0..=index {
        let tail: String = after.lines().skip(offset).collect::<Vec<_>>().join("\n");
        match field_line(&tail, "tets") {
            0 => return field_line(text, last),
            l => offset += l,
        }
    }
    let region_start = offset - 1;
    let tail: String = after
        .lines()
        .skip(region_start)
        .collect::<Vec<_>>()
        .join("\n");
    match field_line(&tail, last) {
        0 => start + region_start,
        l => start + region_start + l - 1,
    }
}

/// 1-based line of the first `name:` (or `name` for quoted keys) outside comments; 0 when absent.
fn field_line(text: &str, name: &str) -> usize {
    let key = if name.starts_with('"') {
        name.to_string()
    } else {
        format!("{name}:")
    };
    text.lines()
        .position(|l| {
            let code = l.split("//").next().unwrap_or("");
            code.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == '"' || c == ':'))
                .any(|tok| tok == key || tok.starts_with(&key))
        })
        .map_or(0, |i| i + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"(
        name: "t",
        mesh: Generate(Block(min: (0, 0, 0), size: (0.1, 0.02, 0.02), cells: (5, 1, 1))),
        material: Custom((youngs_modulus: 1e4, poisson_ratio: 0.3, density: 1000)),
        duration: 1.0,
    )"#;

    #[test]
    fn good_scene_parses_with_defaults() {
        let s = parse_scene(GOOD, Path::new("t.ron")).unwrap();
        assert_eq!(s.solver.substeps, 10);
        assert!(s.cutting.is_none());
    }

    #[test]
    fn unknown_field_names_line_column_and_field() {
        let bad = GOOD.replace("duration: 1.0,", "duration: 1.0,\n        durashun: 2.0,");
        let e = parse_scene(&bad, Path::new("t.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.ron:6:"), "{e}");
        assert!(e.contains("durashun"), "{e}");
    }

    #[test]
    fn bad_value_names_field_and_line() {
        let bad = GOOD.replace(
            "duration: 1.0,",
            "duration: 1.0,\n        solver: (substeps: 0),",
        );
        let e = parse_scene(&bad, Path::new("t.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.ron:6: solver.substeps"), "{e}");
        let bad = GOOD.replace("duration: 1.0", "duration: -1.0");
        let e = parse_scene(&bad, Path::new("t.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.ron:5: duration"), "{e}");
    }

    /// A solver scheme asked of a method that has no tet solver is refused at its line,
    /// not silently ignored.
    #[test]
    fn a_scheme_for_a_method_without_one_is_refused_at_its_line() {
        let nakao = GOOD.replace(
            "duration: 1.0,",
            "duration: 1.0,\n        model: MassSpring(()),\n        solver: (scheme: Newton(())),",
        );
        let e = parse_scene(&nakao, Path::new("t.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.ron:7: solver.scheme"), "{e}");
        assert!(
            e.contains("Newton") && e.contains("remove this field"),
            "{e}"
        );
        let xpbd = GOOD.replace(
            "duration: 1.0,",
            "duration: 1.0,\n        solver: (scheme: Newton(())),",
        );
        assert!(parse_scene(&xpbd, Path::new("t.ron")).is_ok());
    }

    #[test]
    fn missing_material_and_region_fields_are_located() {
        let bare = GOOD.replace(
            "material: Custom((youngs_modulus: 1e4, poisson_ratio: 0.3, density: 1000)),\n",
            "",
        );
        let e = parse_scene(&bare, Path::new("t.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("material is missing"), "{e}");
        let text = "(\n model: Rheology((\n  material: \"a\",\n  regions: [\n   (tets: Tets([0]), material: \"b\"),\n   (\n    tets: Tets([]),\n    material: \"c\",\n   ),\n  ],\n )),\n)";
        assert_eq!(locate(text, "model.material"), 3);
        assert_eq!(locate(text, "model.regions[0].material"), 5);
        assert_eq!(locate(text, "model.regions[1].tets"), 7);
        assert_eq!(locate(text, "model.regions[1].material"), 8);
    }

    #[test]
    fn shipped_scenes_all_parse() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
        for entry in std::fs::read_dir(&root).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.ends_with(".ron") && name != "materials.ron" && name != "rheology.ron" {
                load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
            }
        }
    }

    #[test]
    fn shipped_materials_all_load() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let m = load_materials(&root.join("config/materials.ron")).unwrap();
        assert!(m["small_intestine"].youngs_modulus > 1e4);
        assert_eq!(m.len(), 5);
    }
}
