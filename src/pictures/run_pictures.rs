//! The pictures `incise run --screenshot-every N` takes of a body: the XPBD solver's
//! screenshots (its tool and an exercise's plan drawn), or any method's tet views.

use std::path::Path;

use anyhow::{Result, bail};
use incise_xr::Overlays;

use super::plan_decal::PlanDecal;
use super::screenshots::{ImageSize, Screenshots};
use super::view_pictures::ViewPictures;
use crate::sim_body::SimBody;

/// An offscreen renderer for one run's body.
pub enum RunPictures {
    /// Of an XPBD solver (CPU or GPU), with its tool and decal.
    Solver(Box<Screenshots>),
    /// Of any method's tet view, with the heat map of its quantity.
    Views(Box<ViewPictures>),
}

impl RunPictures {
    /// An offscreen renderer of `size` for `body`: an XPBD body's own pictures (its tool
    /// and `decal`, an exercise's plan), else pictures of its tet view with the heat map
    /// of its quantity (a decal is an error there).
    pub fn for_body(
        body: &dyn SimBody,
        size: ImageSize,
        decal: Option<&PlanDecal>,
    ) -> Result<Self> {
        let Some(parts) = body.solver_parts() else {
            if decal.is_some() {
                bail!(
                    "an exercise's plan is drawn on XPBD bodies only; this body's method is {}",
                    body.method().name()
                );
            }
            let heat_map = Overlays {
                stress: true,
                ..Overlays::default()
            };
            return Ok(RunPictures::Views(Box::new(ViewPictures::new(
                size, heat_map,
            )?)));
        };
        let shots = Screenshots::new(
            None,
            parts.body.solver(),
            parts.skin,
            size,
            Default::default(),
        )?;
        let shots = match parts.tool {
            Some(t) => shots.with_tool(t),
            None => shots,
        };
        Ok(RunPictures::Solver(Box::new(match decal {
            Some(d) => shots.with_decal(d.clone()),
            None => shots,
        })))
    }

    /// A picture of `body` now.
    pub fn image(&mut self, body: &dyn SimBody) -> Result<incise_xr::RgbaImage> {
        match (self, body.solver_parts()) {
            (RunPictures::Solver(s), Some(parts)) => s.image(parts.body),
            (RunPictures::Views(v), _) => v.image(body.tet_view()),
            (RunPictures::Solver(_), None) => bail!(
                "XPBD screenshots cannot draw a {} body",
                body.method().name()
            ),
        }
    }

    /// Draw `body` now into the PNG `path`.
    pub fn save(&mut self, body: &dyn SimBody, path: &Path) -> Result<()> {
        match (self, body.solver_parts()) {
            (RunPictures::Solver(s), Some(parts)) => s.save(parts.body, path),
            (RunPictures::Views(v), _) => v.save(body.tet_view(), body.scalpel_pose(), path),
            (RunPictures::Solver(_), None) => bail!(
                "XPBD screenshots cannot draw a {} body",
                body.method().name()
            ),
        }
    }
}
