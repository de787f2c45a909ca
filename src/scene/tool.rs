//! The scene's scalpel: which tool file and which stroke drives it (issue 5).

use std::path::Path;

use anyhow::{Context, Result};
use incise_scalpel::{Stroke, Tool, ToolStroke, load_stroke, load_tool};
use serde::Deserialize;

/// The scalpel of a scene: a tool file, relative to the scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolSpec {
    /// Tool file (RON, e.g. `tools/scalpel_10.ron`), relative to the scene file.
    pub file: String,
    /// A dull blade: the edge spheres push but never cut.
    #[serde(default)]
    pub dull: bool,
}

/// Load the tool and build the stroke of a scene.
pub fn load(tool: &ToolSpec, stroke: &ToolStroke, scene_path: &Path) -> Result<(Tool, Stroke)> {
    let dir = scene_path.parent().unwrap_or(Path::new("."));
    let t = load_tool(&dir.join(&tool.file))
        .with_context(|| format!("{}: tool", scene_path.display()))?;
    let s = match stroke {
        ToolStroke::File(f) => load_stroke(&dir.join(f))
            .with_context(|| format!("{}: stroke", scene_path.display()))?,
        ToolStroke::Incision(i) => i
            .stroke(&t)
            .with_context(|| format!("{}: stroke.Incision", scene_path.display()))?,
    };
    Ok((t, s))
}
