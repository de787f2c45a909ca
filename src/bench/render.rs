//! `incise bench render`: offscreen frame time of the renderer alone on the Nakao plate
//! and the intestine with a skin of at least 200k triangles (`--case`; `--scaling` adds
//! the ≈140k–1.1M-tet intestines), at 1920×1080 (one view) and at Quest 3 stereo
//! resolution (two 2064×2208 eyes), after warm-up frames, with the node positions from
//! the host or from the GPU solver on the device (`--device`). GPU time comes from timestamps
//! where the adapter has them; wall time (submit to idle) always.

use std::time::Instant;

use anyhow::Result;
use incise_sim::generate::{IntestineParams, intestine};
use incise_sim::gpu::GpuSolver;
use incise_sim::skin::Skin;
use incise_sim::{Material, Solver, SolverParams, TetMesh};
use incise_xr::{Camera, OffscreenRenderer, RenderDevice, RenderSettings, UncutBody, View};
use serde::Serialize;

use super::BenchCase;
use crate::sim_body::{DeviceChoice, auto_device};

/// The GPU body's material: it is not stepped (only its buffers are read); soft enough
/// for the default substeps on every benchmark mesh, so the solver accepts it.
const RENDER_MATERIAL: Material = Material {
    youngs_modulus: 50.0,
    poisson_ratio: 0.45,
    density: 1000.0,
};

/// Smallest skin the benchmark draws, triangles (issue 6).
pub const MIN_SKIN_TRIANGLES: usize = 200_000;
/// Distance between the eyes of the stereo case, m.
const EYE_SEPARATION: f32 = 0.063;

/// One resolution's timings.
#[derive(Debug, Clone, Serialize)]
pub struct RenderBenchResult {
    /// Body and resolution, e.g. "intestine 1920x1080" or "plate stereo 2x2064x2208".
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

/// One body of the render benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct BenchBody {
    /// "plate", "intestine" or "intestine-NNNk".
    pub name: String,
    /// Tets of the body.
    pub tets: usize,
    /// Skin triangles drawn.
    pub skin_triangles: usize,
}

/// Whole render benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct RenderBenchReport {
    /// The render adapter.
    pub adapter: String,
    /// CPU model and cores.
    pub machine: String,
    /// Where the node positions came from: "cpu" (host upload) or "gpu" (the GPU
    /// solver's displacement buffer on the render device).
    pub positions_from: String,
    /// The bodies drawn.
    pub bodies: Vec<BenchBody>,
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

/// The bodies `case` and `scaling` ask for: the Nakao plate (its boundary as the skin),
/// the intestine with a ≥ 200k-triangle skin, and the intestine scaling series.
fn bodies(case: BenchCase, scaling: bool) -> Result<Vec<(String, TetMesh, Skin)>> {
    let mut out = Vec::new();
    if matches!(case, BenchCase::All | BenchCase::Plate) {
        let (mesh, _) = TetMesh::from_raw(incise_sim::generate::plate())?;
        let skin = Skin::from_boundary(&mesh);
        out.push(("plate".to_string(), mesh, skin));
    }
    if matches!(case, BenchCase::All | BenchCase::Intestine) {
        let (mesh, skin) = fine_intestine(MIN_SKIN_TRIANGLES);
        out.push(("intestine".to_string(), mesh, skin));
    }
    if scaling {
        for n in [140_000, 550_000, 1_100_000] {
            let p = IntestineParams::with_target_tets(n);
            let (raw, surface) = intestine(&p);
            let (mesh, _) = TetMesh::from_raw(raw)?;
            let skin = Skin::embed(&mesh, surface);
            out.push((format!("intestine-{}k", p.tet_count() / 1000), mesh, skin));
        }
    }
    Ok(out)
}

/// Median wall and GPU ms of `frames` frames of `views` views of `w`×`h` (3 warm-up).
fn time_views(
    dev: &RenderDevice,
    (mesh, skin): (&TetMesh, &Skin),
    state: &incise_xr::BodyState<'_>,
    (w, h): (u32, u32),
    views: u32,
    frames: u32,
) -> Result<(f64, Option<f64>)> {
    let settings = RenderSettings::default();
    let (lo, hi) = mesh.rest_bounds();
    let mut r = OffscreenRenderer::new(dev, mesh, skin, (w, h), views)?;
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
        r.render(state, &settings, &eye_views);
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
    Ok((
        median(&mut wall),
        (!gpu.is_empty()).then(|| median(&mut gpu)),
    ))
}

/// Run the render benchmark: `frames` timed frames per body of `case` (plus the scaling
/// series) and resolution, after 3 warm-up frames. `device` says where the node
/// positions come from: `cpu`, the host (uploaded every frame, as with the CPU solver);
/// `gpu`, a GPU solver's displacement buffer on the render device (the renderer adds
/// the rest positions in a compute pass); `auto`, what `--device auto` picks.
pub fn run(
    frames: u32,
    json: bool,
    case: BenchCase,
    device: DeviceChoice,
    scaling: bool,
) -> Result<()> {
    let dev = RenderDevice::headless()?;
    let device = match device {
        DeviceChoice::Auto => auto_device(&dev.info).0,
        d => d,
    };
    let mut results = Vec::new();
    let mut bodies_run = Vec::new();
    for (body_name, mesh, skin) in bodies(case, scaling)? {
        let gpu_body = match device {
            DeviceChoice::Gpu => {
                let solver = Solver::new(mesh.clone(), RENDER_MATERIAL, SolverParams::default())?;
                Some(GpuSolver::new(solver, &dev.compute_context())?)
            }
            _ => None,
        };
        let body = UncutBody::new(&mesh);
        let mut state = body.state(&mesh.rest_positions);
        state.device_displacements = gpu_body.as_ref().map(|g| g.displacement_buffer());
        bodies_run.push(BenchBody {
            name: body_name.clone(),
            tets: mesh.tet_count(),
            skin_triangles: skin.surface.triangles.len(),
        });
        for (res, size, views) in [
            ("1920x1080", (1920, 1080), 1u32),
            ("stereo 2x2064x2208", (2064, 2208), 2),
        ] {
            let (wall, gpu) = time_views(&dev, (&mesh, &skin), &state, size, views, frames)?;
            let res = RenderBenchResult {
                case: format!("{body_name} {res}"),
                views,
                width: size.0,
                height: size.1,
                wall_ms_median: wall,
                gpu_ms_median: gpu,
            };
            if !json {
                println!(
                    "{:<30} wall {:>9.2} ms/frame   gpu {}",
                    res.case,
                    res.wall_ms_median,
                    res.gpu_ms_median
                        .map_or("n/a (no timestamps)".into(), |g| format!("{g:.3} ms/frame"))
                );
            }
            results.push(res);
        }
    }
    let report = RenderBenchReport {
        adapter: dev.describe(),
        machine: crate::provenance::machine(),
        positions_from: match device {
            DeviceChoice::Gpu => "gpu".into(),
            _ => "cpu".into(),
        },
        bodies: bodies_run,
        frames,
        results,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        for b in &report.bodies {
            println!(
                "{}: {} tets, {} skin triangles",
                b.name, b.tets, b.skin_triangles
            );
        }
        println!(
            "node positions from the {}; adapter {}; {}",
            report.positions_from, report.adapter, report.machine
        );
    }
    Ok(())
}
