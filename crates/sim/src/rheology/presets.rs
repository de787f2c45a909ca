//! Named rheological materials from a RON file (`config/rheology.ron`): a map from preset
//! name to [`RheologyMaterial`], each checked, with errors naming file, line and field.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::material::RheologyMaterial;
use crate::ron_file::{self, ReadError, SyntaxError};

/// Why a preset file could not be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PresetError {
    /// The file could not be read.
    #[error(transparent)]
    Io(#[from] ReadError),
    /// RON syntax, unknown or missing field, wrong type.
    #[error(transparent)]
    Syntax(#[from] SyntaxError),
    /// A value is out of range.
    #[error("{path}:{line}: preset \"{preset}\": {field} {message}")]
    Value {
        /// The file.
        path: PathBuf,
        /// 1-based line of the preset's name (0 if not found).
        line: usize,
        /// Preset name.
        preset: String,
        /// Offending field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A requested preset is not in the file.
    #[error("{path}: no preset named \"{name}\" (the file has: {known})")]
    Missing {
        /// The file.
        path: PathBuf,
        /// The name asked for.
        name: String,
        /// The names it has, comma-separated.
        known: String,
    },
}

/// The presets of one file.
#[derive(Debug, Clone, PartialEq)]
pub struct RheologyPresets {
    /// Where they came from (for error messages).
    pub path: PathBuf,
    /// Preset name → material, in name order.
    pub materials: BTreeMap<String, RheologyMaterial>,
}

impl RheologyPresets {
    /// Read and check a preset file.
    pub fn load(path: &Path) -> Result<Self, PresetError> {
        let text = ron_file::read(path)?;
        Self::parse(&text, path)
    }

    /// Parse and check preset text; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, PresetError> {
        let materials: BTreeMap<String, RheologyMaterial> = ron_file::parse(text, path)?;
        for (name, m) in &materials {
            if let Some((field, message)) = m.problem() {
                let key = format!("\"{name}\"");
                let line = text
                    .lines()
                    .position(|l| l.split("//").next().unwrap_or("").contains(&key))
                    .map_or(0, |i| i + 1);
                return Err(PresetError::Value {
                    path: path.into(),
                    line,
                    preset: name.clone(),
                    field: field.into(),
                    message,
                });
            }
        }
        Ok(RheologyPresets {
            path: path.into(),
            materials,
        })
    }

    /// The preset called `name`.
    pub fn get(&self, name: &str) -> Result<RheologyMaterial, PresetError> {
        self.materials
            .get(name)
            .copied()
            .ok_or_else(|| PresetError::Missing {
                path: self.path.clone(),
                name: name.into(),
                known: self
                    .materials
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{
        // a comment
        "putty": (
            stiffness: 50.0, voigt_viscosity: 0.1, damper: Linear(1.0),
            rest_ratio: 0.5, ratio_min: 0.1, ratio_max: 0.9, density: 1000.0,
        ),
    }"#;

    #[test]
    fn good_file_parses() {
        let p = RheologyPresets::parse(GOOD, Path::new("r.ron")).unwrap();
        assert_eq!(p.get("putty").unwrap().stiffness, 50.0);
        let e = p.get("clay").unwrap_err().to_string();
        assert!(e.contains("\"clay\"") && e.contains("putty"), "{e}");
    }

    #[test]
    fn out_of_range_value_names_line_preset_and_field() {
        let bad = GOOD.replace("ratio_max: 0.9", "ratio_max: 1.5");
        let e = RheologyPresets::parse(&bad, Path::new("r.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.ron:3: preset \"putty\": ratio_min"), "{e}");
    }

    #[test]
    fn unknown_field_names_line_and_field() {
        let bad = GOOD.replace("density: 1000.0,", "density: 1000.0, densty: 1.0,");
        let e = RheologyPresets::parse(&bad, Path::new("r.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.ron:5:"), "{e}");
        assert!(e.contains("densty"), "{e}");
    }
}
