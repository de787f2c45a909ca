//! The scalpel when a hand drives it (the preview's mouse, a recorded stroke replayed with
//! `incise run --stroke`): the scene's tool, else the built-in No. 10 blade. A hand never
//! changes where the scene may release tets (its `cut_zone`): a tearing scene tears in the
//! preview, the headset and a replay as it does in `incise run`. The preview's panel can
//! switch a cutting scene to [`edge_zone`] for the session, in view.

use std::path::Path;

use anyhow::{Context, Result};
use incise_scalpel::{Tool, parse_tool};
use incise_sim::contact::CutZone;

/// Where the built-in tool's file lives in the source tree (named in its errors).
pub const DEFAULT_TOOL_FILE: &str = "config/tools/scalpel_10.ron";

/// The built-in tool's RON text (the shipped No. 10 blade, compiled in so a scene
/// anywhere on disk gets it).
const DEFAULT_TOOL_TEXT: &str = include_str!("../../config/tools/scalpel_10.ron");

/// Reach of the cut zone the preview's "only along the blade" switch gives, as a fraction
/// of the mesh's mean tet edge length: `plate_cut.ron`'s 0.5 mm on its 2.5 mm tets.
pub const HAND_REACH_FACTOR: f32 = 0.2;

/// The built-in No. 10 scalpel (`config/tools/scalpel_10.ron`).
pub fn default_tool() -> Result<Tool> {
    parse_tool(DEFAULT_TOOL_TEXT, Path::new(DEFAULT_TOOL_FILE)).context("the built-in scalpel")
}

/// The cut zone along a blade's edge on a mesh of `mean_edge` (m):
/// `NearEdge(reach = HAND_REACH_FACTOR × mean_edge)` (PHYSICS.md §1.4–1.5).
pub fn edge_zone(mean_edge: f32) -> CutZone {
    CutZone::NearEdge {
        reach: HAND_REACH_FACTOR * mean_edge,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_tool_loads_and_the_edge_zone_scales_with_the_mesh() {
        let t = default_tool().unwrap();
        assert_eq!(t.name(), "scalpel_10");
        assert_eq!(edge_zone(0.0025), CutZone::NearEdge { reach: 0.0005 });
    }
}
