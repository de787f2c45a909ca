//! Reading scene and material files, with errors that name file, line, column and field.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use incise_sim::Material;

use super::{MaterialChoice, Scene};

/// Why a scene or material file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// RON syntax, unknown field, wrong type: ron's position and message.
    #[error("{path}:{line}:{col}: {msg}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        col: usize,
        /// ron's message (names the field).
        msg: String,
    },
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
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.into(),
        source,
    })?;
    parse_scene(&text, path)
}

/// Parse and validate scene text; `path` names it in errors.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let scene: Scene = ron::from_str(text).map_err(|e| syntax(path, e))?;
    let value_err = |field: &str, msg: String| SceneError::Value {
        path: path.into(),
        line: field_line(text, field.rsplit('.').next().unwrap_or(field)),
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
    if let super::ModelChoice::MassSpring(ms) = &scene.model {
        ms.validate()
            .map_err(|(field, msg)| value_err(&field, msg))?;
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
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.into(),
        source,
    })?;
    let map: BTreeMap<String, Material> = ron::from_str(&text).map_err(|e| syntax(path, e))?;
    for (name, m) in &map {
        m.validate().map_err(|e| SceneError::Value {
            path: path.into(),
            line: field_line(&text, &format!("\"{name}\"")),
            field: name.clone(),
            msg: e.to_string(),
        })?;
    }
    Ok(map)
}

fn syntax(path: &Path, e: ron::error::SpannedError) -> SceneError {
    SceneError::Syntax {
        path: path.into(),
        line: e.span.start.line,
        col: e.span.start.col,
        msg: e.code.to_string(),
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

    #[test]
    fn shipped_materials_all_load() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let m = load_materials(&root.join("config/materials.ron")).unwrap();
        assert!(m["small_intestine"].youngs_modulus > 1e4);
        assert_eq!(m.len(), 5);
    }
}
