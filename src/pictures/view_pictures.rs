//! Offscreen pictures of a body of any method, drawn from its [`TetView`] as the preview
//! draws it: the current topology's skin and cut faces, the heat map of the method's own
//! quantity, and a fixed camera framing the first picture's body.

use std::path::Path;

use anyhow::{Context, Result};
use incise_sim::contact::ToolPose;
use incise_xr::frame::ToolState;
use incise_xr::{OffscreenRenderer, Overlays, RenderDevice, RenderSettings, RgbaImage, View};

use super::screenshots::{ImageSize, default_camera};
use super::tet_drawing::TetDrawing;
use super::tool_view::pose_matrix;
use crate::sim_body::TetView;

/// An offscreen renderer of a body's tet views, rebuilt when a cut changes the tets.
pub struct ViewPictures {
    dev: RenderDevice,
    size: ImageSize,
    overlays: Overlays,
    drawing: Option<TetDrawing>,
    offscreen: Option<OffscreenRenderer>,
    camera: Option<View>,
}

impl ViewPictures {
    /// Pictures of `size` with `overlays` (the heat map is the stress overlay) on a new
    /// headless render device.
    pub fn new(size: ImageSize, overlays: Overlays) -> Result<ViewPictures> {
        let dev = RenderDevice::headless().context("offscreen pictures draw with wgpu")?;
        Ok(ViewPictures {
            dev,
            size,
            overlays,
            drawing: None,
            offscreen: None,
            camera: None,
        })
    }

    /// Take `view` as the body to draw: its drawing updated (the renderer rebuilt when its
    /// topology changed), and the camera framing it if this is the first view.
    pub fn aim(&mut self, view: TetView) -> Result<()> {
        let (d, rebuilt) = match self.drawing.take() {
            Some(mut d) => {
                let changed = d.update(view)?;
                (d, changed)
            }
            None => (TetDrawing::new(view)?, true),
        };
        let d = self.drawing.insert(d);
        let off = match self.offscreen.take().filter(|_| !rebuilt) {
            Some(off) => off,
            None => {
                let (mesh, skin) = (&d.render.mesh, &d.render.skin);
                OffscreenRenderer::new(&self.dev, mesh, skin, (self.size.0, self.size.1), 1)?
            }
        };
        let off = self.offscreen.insert(off);
        self.camera
            .get_or_insert_with(|| default_camera(&d.render.mesh).view(off.aspect()));
        Ok(())
    }

    /// Draw `view` now.
    pub fn image(&mut self, view: TetView) -> Result<RgbaImage> {
        self.image_with_tool(view, None)
    }

    /// Draw `view` now with the scalpel at `tool` (`None`: no scalpel).
    pub fn image_with_tool(&mut self, view: TetView, tool: Option<ToolPose>) -> Result<RgbaImage> {
        self.aim(view)?;
        let (Some(d), Some(off), Some(camera)) = (&self.drawing, &mut self.offscreen, &self.camera)
        else {
            anyhow::bail!("offscreen pictures: no view was taken");
        };
        let settings = RenderSettings {
            overlays: self.overlays,
            stress_max: d.scale,
            tool: ToolState {
                transform: tool.as_ref().map(pose_matrix),
                spheres: Vec::new(),
            },
            ..RenderSettings::default()
        };
        Ok(off.render_image(&d.state(), &settings, camera)?)
    }

    /// Draw `view` (with the scalpel at `tool`) now and write the PNG to `path`.
    pub fn save(&mut self, view: TetView, tool: Option<ToolPose>, path: &Path) -> Result<()> {
        self.image_with_tool(view, tool)?
            .save_png(path)
            .with_context(|| format!("writing screenshot {}", path.display()))
    }
}
