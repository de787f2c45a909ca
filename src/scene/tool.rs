//! The scene's scalpel: which tool file and which stroke drives it (issue 5).

use std::path::Path;

use anyhow::{Context, Result};
use incise_scalpel::{Stroke, Tool, ToolStroke, parse_stroke, parse_tool};
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

/// Load the tool and build the stroke of a scene: files beside the scene, or the built-in
/// copies of config/'s (`built_in::config_text`) for a scene copied out of config/.
pub fn load(tool: &ToolSpec, stroke: &ToolStroke, scene_path: &Path) -> Result<(Tool, Stroke)> {
    let t = load_tool_beside(scene_path, &tool.file)
        .with_context(|| format!("{}: tool", scene_path.display()))?;
    let s = match stroke {
        ToolStroke::File(f) => text_beside(scene_path, f)
            .and_then(|(path, text)| Ok(parse_stroke(&text, &path)?))
            .with_context(|| format!("{}: stroke", scene_path.display()))?,
        ToolStroke::Incision(i) => i
            .stroke(&t)
            .with_context(|| format!("{}: stroke.Incision", scene_path.display()))?,
    };
    Ok((t, s))
}

/// The tool file `file` of the scene at `scene_path`: beside it, or config/'s built-in copy.
pub fn load_tool_beside(scene_path: &Path, file: &str) -> Result<Tool> {
    let (path, text) = text_beside(scene_path, file)?;
    Ok(parse_tool(&text, &path)?)
}

/// The file `file` named by the scene at `scene_path` (`built_in::config_text`): its text
/// and the path that names it.
fn text_beside(scene_path: &Path, file: &str) -> Result<(std::path::PathBuf, String)> {
    let dir = scene_path.parent().unwrap_or(Path::new("."));
    Ok(super::built_in::config_text(dir, file)?)
}
