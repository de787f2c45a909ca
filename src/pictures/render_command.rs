//! `incise render`: a scene stepped a number of frames by its own script and that frame
//! drawn offscreen into a PNG, for every method (the XPBD solver with its skin and tool,
//! any other method's tet view with the heat map of its quantity).

use std::path::Path;

use anyhow::{Context, Result, anyhow};
use incise_xr::{Overlays, RenderDevice};

use super::screenshots::{ImageSize, OverlayArg, Screenshots, overlays, place_on};
use super::view_pictures::ViewPictures;
use crate::sim_body::DeviceChoice;

/// `incise render`: step `scene` for `frame` frames, render the frame, write `out`.
pub fn render_frame(
    scene_path: &Path,
    frame: u64,
    out: &Path,
    size: ImageSize,
    overlay: &[OverlayArg],
    device: DeviceChoice,
) -> Result<()> {
    let scene = crate::scene::load_scene(scene_path)?;
    if !matches!(scene.model, crate::scene::ModelChoice::Xpbd) {
        return render_view_frame(&scene, scene_path, frame, out, size, overlays(overlay));
    }
    let built = crate::scene::build_scene(&scene, scene_path, None)?;
    let dev = RenderDevice::headless()
        .map_err(|e| anyhow!("{e}"))
        .context("incise render draws offscreen with wgpu")?;
    let mut shots = Screenshots::new(
        Some(&dev),
        &built.solver,
        &built.skin,
        size,
        overlays(overlay),
    )?
    .with_shared_device();
    if let Some(t) = &built.tool {
        shots = shots.with_tool(&t.tool);
    }
    let stroke = built.tool.as_ref().and_then(|t| t.stroke.clone());
    let dt = built.solver.params().frame_dt as f64;
    let mut body = place_on(built.solver, device, &dev)?;
    for f in 0..frame {
        // The scene's stroke moves the tool as in `incise run`.
        if let Some(s) = &stroke {
            body.move_tool(s.pose_at((f + 1) as f64 * dt));
        }
        body.step_frame()
            .with_context(|| format!("{}: frame {f}", scene_path.display()))?;
    }
    create_parent(out)?;
    shots.save(&body, out)
}

/// `incise render` of a scene of another method than XPBD: its body stepped `frame`
/// frames by the scene's own script, drawn from its tet view with `overlays` (`stress`:
/// the heat map of the method's quantity).
fn render_view_frame(
    scene: &crate::scene::Scene,
    scene_path: &Path,
    frame: u64,
    out: &Path,
    size: ImageSize,
    overlays: Overlays,
) -> Result<()> {
    let opts = crate::sim_body::OpenOptions {
        device: DeviceChoice::Cpu,
        quiet: true,
        ..Default::default()
    };
    let (mut body, _) = crate::sim_body::open(scene, scene_path, &opts)?;
    let mut pictures = ViewPictures::new(size, overlays)?;
    // The camera frames the body at rest, as for an XPBD scene.
    pictures.aim(body.tet_view())?;
    for f in 0..frame {
        body.step(&crate::sim_body::ToolInput::Script)
            .with_context(|| format!("{}: frame {f}", scene_path.display()))?;
    }
    create_parent(out)?;
    pictures.save(body.tet_view(), body.scalpel_pose(), out)
}

/// Make the folder `path` is to be written in.
fn create_parent(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    Ok(())
}
