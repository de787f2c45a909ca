//! The scalpel when a hand drives it (the preview's mouse, a recorded stroke replayed with
//! `incise run --stroke`): the scene's tool, else the built-in No. 10 blade, and a cut
//! zone along its edge when the scene cuts without naming one. The preview and the replay
//! both build their scene through this rule, so a recording replays the same physics.

use std::path::Path;

use anyhow::{Context, Result};
use incise_scalpel::{Tool, parse_tool};
use incise_sim::contact::CutZone;
use incise_sim::xpbd::SolverParams;

/// Where the built-in tool's file lives in the source tree (named in its errors).
pub const DEFAULT_TOOL_FILE: &str = "config/tools/scalpel_10.ron";

/// The built-in tool's RON text (the shipped No. 10 blade, compiled in so a scene
/// anywhere on disk gets it).
const DEFAULT_TOOL_TEXT: &str = include_str!("../../config/tools/scalpel_10.ron");

/// Reach of the cut zone given to a hand-driven blade, as a fraction of the mesh's mean
/// tet edge length: `plate_cut.ron`'s 0.5 mm on its 2.5 mm tets.
pub const HAND_REACH_FACTOR: f32 = 0.2;

/// The built-in No. 10 scalpel (`config/tools/scalpel_10.ron`).
pub fn default_tool() -> Result<Tool> {
    parse_tool(DEFAULT_TOOL_TEXT, Path::new(DEFAULT_TOOL_FILE)).context("the built-in scalpel")
}

/// A scene that cuts (`release_threshold` set) with the default zone `Anywhere` gets
/// `NearEdge(reach = HAND_REACH_FACTOR × mean_edge)` (m): a hand-held blade releases tets
/// along its edge, not wherever a pull tears (PHYSICS.md §1.4–1.5). Returns whether it
/// changed `params`.
pub fn edge_cut_zone(params: &mut SolverParams, mean_edge: f32) -> bool {
    if params.release_threshold.is_some() && params.cut_zone == CutZone::Anywhere {
        params.cut_zone = CutZone::NearEdge {
            reach: HAND_REACH_FACTOR * mean_edge,
        };
        return true;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_tool_loads_and_only_cutting_scenes_get_a_zone() {
        let t = default_tool().unwrap();
        assert_eq!(t.name(), "scalpel_10");
        let mut p = SolverParams::default();
        assert!(!edge_cut_zone(&mut p, 0.0025));
        assert_eq!(p.cut_zone, CutZone::Anywhere);
        p.release_threshold = Some(1e3);
        assert!(edge_cut_zone(&mut p, 0.0025));
        assert_eq!(p.cut_zone, CutZone::NearEdge { reach: 0.0005 });
        // A zone the scene named is kept.
        p.cut_zone = CutZone::NearEdge { reach: 0.001 };
        assert!(!edge_cut_zone(&mut p, 0.0025));
        assert_eq!(p.cut_zone, CutZone::NearEdge { reach: 0.001 });
    }
}
