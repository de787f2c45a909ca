//! `incise bench render`: offscreen frame time of the renderer alone on the intestine with
//! a skin of at least 200k triangles, at 1920×1080 (one view) and at Quest 3 stereo
//! resolution (two 2064×2208 eyes), after warm-up frames. GPU time comes from timestamps
//! where the adapter has them; wall time (submit to idle) always.

use std::time::Instant;

use anyhow::Result;
use incise_sim::TetMesh;
use incise_sim::generate::{IntestineParams, intestine};
use incise_sim::skin::Skin;
use incise_xr::{Camera, OffscreenRenderer, RenderDevice, RenderSettings, UncutBody, View};
use serde::Serialize;

/// Smallest skin the benchmark draws, triangles (issue 6).
pub const MIN_SKIN_TRIANGLES: usize = 200_000;
/// Distance between the eyes of the stereo case, m.
const EYE_SEPARATION: f32 = 0.063;

/// One resolution's timings.
#[derive(Debug, Clone, Serialize)]
pub struct RenderBenchResult {
    /// "1920x1080" or "stereo 2x2064x2208".
    pub case: String,
    /// Views (eyes) per frame.
    pub views: u32,
    /// Pixels per view.
    pub width: u32,
    /// Pixels per view.
    pub height: u32,
    /// Median wall time per frame (encode, submit, wait for the device), ms.
    pub wall_ms_median: f64,
    /// Median GPU time per frame (skin pass to last view), ms, where timestamps exist.
    pub gpu_ms_median: Option<f64>,
}

/// Whole render benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct RenderBenchReport {
    /// The render adapter.
    pub adapter: String,
    /// CPU model and cores.
    pub machine: String,
    /// Tets of the body.
    pub tets: usize,
    /// Skin triangles drawn.
    pub skin_triangles: usize,
    /// Frames timed per case.
    pub frames: u32,
    /// Results per resolution.
    pub results: Vec<RenderBenchResult>,
}

/// The intestine with its skin refined until it has at least `min` triangles.
pub fn fine_intestine(min: usize) -> (TetMesh, Skin) {
    let mut p = IntestineParams::default();
    loop {
        let (raw, surface) = intestine(&p);
        if surface.triangles.len() >= min || p.skin_refine >= 64 {
            let mesh = TetMesh::from_raw(raw)
                .expect("the generated intestine is valid")
                .0;
            let skin = Skin::embed(&mesh, surface);
            return (mesh, skin);
        }
        p.skin_refine += 1;
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// Run the render benchmark: `frames` timed frames per case after 3 warm-up frames.
pub fn run(frames: u32, json: bool) -> Result<()> {
    let dev = RenderDevice::headless()?;
    let (mesh, skin) = fine_intestine(MIN_SKIN_TRIANGLES);
    let body = UncutBody::new(&mesh);
    let state = body.state(&mesh.rest_positions);
    let settings = RenderSettings::default();
    let (lo, hi) = mesh.rest_bounds();
    let mut results = Vec::new();
    for (case, (w, h), views) in [
        ("1920x1080", (1920, 1080), 1u32),
        ("stereo 2x2064x2208", (2064, 2208), 2),
    ] {
        let mut r = OffscreenRenderer::new(&dev, &mesh, &skin, (w, h), views)?;
        let timed = r.renderer.enable_gpu_timing();
        let mut cam = Camera::framing(lo, hi, -1.1, 0.6);
        cam.zoom(0.75);
        let centre = cam.view(w as f32 / h as f32);
        // Eyes apart along the view's right axis.
        let right = centre.view.inverse().x_axis.truncate();
        let eye_views: Vec<View> = (0..views)
            .map(|i| {
                let offset = if views == 1 {
                    0.0
                } else {
                    (i as f32 - 0.5) * EYE_SEPARATION
                };
                View {
                    view: centre.view * glam::Mat4::from_translation(-right * offset),
                    proj: centre.proj,
                }
            })
            .collect();
        let (mut wall, mut gpu) = (Vec::new(), Vec::new());
        for f in 0..frames + 3 {
            let t0 = Instant::now();
            r.render(&state, &settings, &eye_views);
            r.wait()?;
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            let g = if timed {
                r.renderer.last_gpu_ms()?
            } else {
                None
            };
            if f >= 3 {
                wall.push(ms);
                gpu.extend(g);
            }
        }
        let res = RenderBenchResult {
            case: case.into(),
            views,
            width: w,
            height: h,
            wall_ms_median: median(&mut wall),
            gpu_ms_median: (!gpu.is_empty()).then(|| median(&mut gpu)),
        };
        if !json {
            println!(
                "{:<20} wall {:>9.2} ms/frame   gpu {}",
                res.case,
                res.wall_ms_median,
                res.gpu_ms_median
                    .map_or("n/a (no timestamps)".into(), |g| format!("{g:.3} ms/frame"))
            );
        }
        results.push(res);
    }
    let report = RenderBenchReport {
        adapter: dev.describe(),
        machine: crate::bench::machine(),
        tets: mesh.tet_count(),
        skin_triangles: skin.surface.triangles.len(),
        frames,
        results,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "intestine: {} tets, {} skin triangles; adapter {}; {}",
            report.tets, report.skin_triangles, report.adapter, report.machine
        );
    }
    Ok(())
}
