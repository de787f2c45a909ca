//! Opening a scene's body: the method its `model` names, with the report's head.

use std::path::Path;

use anyhow::Result;

use super::interface::{OpenOptions, SimBody};
use crate::report::Report;
use crate::scene::{ModelChoice, Scene};

/// The body of `scene` (read from `path`) as `opts` asks, and the head of its report.
pub fn open(scene: &Scene, path: &Path, opts: &OpenOptions) -> Result<(Box<dyn SimBody>, Report)> {
    Ok(match &scene.model {
        ModelChoice::Xpbd => {
            let (body, report) = super::xpbd::open(scene, path, opts)?;
            (Box::new(body), report)
        }
        ModelChoice::MassSpring(ms) => super::nakao_open::open(scene, ms, path, opts)?,
        ModelChoice::Rheology(rh) => {
            let (body, report) = super::rheology_open::open(scene, rh, path, opts)?;
            (Box::new(body), report)
        }
    })
}
