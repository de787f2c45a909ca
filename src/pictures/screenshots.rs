//! Offscreen pictures of a scene from the incise-xr renderer: `incise render` (one frame)
//! and `incise run --screenshot-every K` (a PNG every K frames). No window needed; any
//! wgpu adapter will do (lavapipe without a GPU).

use std::path::Path;
use std::str::FromStr;

use anyhow::{Context, Result};
use clap::ValueEnum;
use incise_sim::gpu::GpuSolver;
use incise_sim::skin::Skin;
use incise_sim::{Solver, TetMesh};
use incise_xr::{
    BodyState, Camera, OffscreenRenderer, Overlays, RenderDevice, RenderSettings, RgbaImage, View,
};

use super::plan_decal::PlanDecal;
use crate::sim_body::{Body, DeviceChoice, auto_device};

/// An image size `WIDTHxHEIGHT` given on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageSize(pub u32, pub u32);

impl FromStr for ImageSize {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("expected WIDTHxHEIGHT such as 1280x720, got \"{s}\""))?;
        let parse = |v: &str| {
            v.trim()
                .parse::<u32>()
                .ok()
                .filter(|&n| (1..=16384).contains(&n))
                .ok_or_else(|| format!("\"{v}\" is not a size of 1 to 16384 pixels"))
        };
        Ok(ImageSize(parse(w)?, parse(h)?))
    }
}

impl std::fmt::Display for ImageSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.0, self.1)
    }
}

/// Overlays that can be switched on from the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OverlayArg {
    /// von Mises heat map on the tet surface.
    Stress,
    /// Edges of the live tets.
    Wireframe,
    /// Pinned nodes.
    Pinned,
    /// The scalpel's contact spheres at its pose.
    ToolSpheres,
}

/// The overlay switches for a list of `--overlay` values.
pub fn overlays(list: &[OverlayArg]) -> Overlays {
    Overlays {
        stress: list.contains(&OverlayArg::Stress),
        wireframe: list.contains(&OverlayArg::Wireframe),
        pinned: list.contains(&OverlayArg::Pinned),
        tool_spheres: list.contains(&OverlayArg::ToolSpheres),
    }
}

/// The default view of a mesh: from the front left and above, the whole rest mesh in view.
pub fn default_camera(mesh: &TetMesh) -> Camera {
    let (lo, hi) = mesh.rest_bounds();
    let mut cam = Camera::framing(lo, hi, -1.1, 0.6);
    cam.zoom(0.75);
    cam
}

/// Put `solver` on the chosen device; a GPU body is opened on `dev`, so the renderer can
/// copy its node positions on the device. `auto` is decided by [`auto_device`] from
/// `dev`'s adapter (a software one gets the CPU solver).
pub fn place_on(solver: Solver, choice: DeviceChoice, dev: &RenderDevice) -> Result<Body> {
    let choice = match choice {
        DeviceChoice::Auto => auto_device(&dev.info).0,
        c => c,
    };
    Ok(match choice {
        DeviceChoice::Gpu => Body::Gpu(Box::new(GpuSolver::new(solver, &dev.compute_context())?)),
        _ => Body::Cpu(Box::new(solver)),
    })
}

/// An offscreen renderer for one body with a fixed camera.
pub struct Screenshots {
    offscreen: OffscreenRenderer,
    view: View,
    settings: RenderSettings,
    pinned: Vec<u32>,
    /// Whether a GPU body lives on this renderer's device.
    shared_device: bool,
    /// Whether the solver's tool is drawn (its mesh given by [`Screenshots::with_tool`]).
    draw_tool: bool,
    /// A planned incision drawn on the tissue (where it is not cut away).
    decal: Option<PlanDecal>,
}

impl Screenshots {
    /// A `size` renderer for `solver`'s mesh and `skin` on `dev` (or a new headless device).
    pub fn new(
        dev: Option<&RenderDevice>,
        solver: &Solver,
        skin: &Skin,
        size: ImageSize,
        overlays: Overlays,
    ) -> Result<Self> {
        let own;
        let dev = match dev {
            Some(d) => d,
            None => {
                own = RenderDevice::headless()?;
                &own
            }
        };
        let offscreen = OffscreenRenderer::new(dev, solver.mesh(), skin, (size.0, size.1), 1)?;
        let view = default_camera(solver.mesh()).view(offscreen.aspect());
        Ok(Screenshots {
            offscreen,
            view,
            settings: RenderSettings {
                overlays,
                stress_max: crate::sim_body::xpbd::stress_scale(solver),
                ..RenderSettings::default()
            },
            pinned: solver.pinned_nodes(),
            shared_device: false,
            draw_tool: false,
            decal: None,
        })
    }

    /// Draw `tool` (its own mesh) wherever the solver's tool is, with its contact spheres
    /// when that overlay is on.
    pub fn with_tool(mut self, tool: &incise_scalpel::Tool) -> Self {
        self.offscreen
            .renderer
            .set_tool_mesh(&crate::pictures::tool_view::tool_mesh(tool));
        self.draw_tool = true;
        self
    }

    /// Draw `decal` (an exercise's plan) on the tissue, following its deformation.
    pub fn with_decal(mut self, decal: PlanDecal) -> Self {
        self.decal = Some(decal);
        self
    }

    /// Declare that GPU bodies given to [`Screenshots::save`] live on this renderer's device.
    pub fn with_shared_device(mut self) -> Self {
        self.shared_device = true;
        self
    }

    /// Render `body` now and write the PNG to `path`.
    pub fn save(&mut self, body: &Body, path: &Path) -> Result<()> {
        self.image(body)?
            .save_png(path)
            .with_context(|| format!("writing screenshot {}", path.display()))
    }

    /// Render `body` now.
    pub fn image(&mut self, body: &Body) -> Result<RgbaImage> {
        let solver = body.solver();
        if self.draw_tool {
            self.settings.tool = crate::pictures::tool_view::tool_state(solver);
        }
        self.settings.lines = self
            .decal
            .iter()
            .map(|d| d.line_uncut(solver.positions(), solver.cut().live()))
            .collect();
        let state = BodyState {
            positions: solver.positions(),
            device_displacements: match (body, self.shared_device) {
                (Body::Gpu(g), true) => Some(g.displacement_buffer()),
                _ => None,
            },
            cut: solver.cut(),
            heat: solver.von_mises(),
            pinned: &self.pinned,
        };
        Ok(self
            .offscreen
            .render_image(&state, &self.settings, &self.view)?)
    }
}
