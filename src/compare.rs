//! `incise compare`: run a scene on the CPU reference and on the GPU side by side and
//! report how far they drift apart (issue 4's parity criterion, as a user-facing check).

use std::path::Path;

use anyhow::{Result, bail};
use serde::Serialize;

use crate::scene::{build_scene, load_scene};
use crate::sim_body::{Body, DeviceChoice};

/// Largest position difference allowed, as a fraction of the mesh's bounding-box diagonal.
pub const POSITION_TOLERANCE: f32 = 1e-4;

/// What the comparison found.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Scene name.
    pub scene: String,
    /// Frames compared.
    pub frames: u64,
    /// GPU adapter.
    pub device: String,
    /// Mesh bounding-box diagonal, m.
    pub mesh_size: f32,
    /// Largest node distance between the two runs over all frames, m.
    pub max_position_difference: f32,
    /// Frame of that largest distance.
    pub worst_frame: u64,
    /// Tets released by the CPU run.
    pub released_cpu: usize,
    /// Tets released by the GPU run.
    pub released_gpu: usize,
    /// Tets released by one run and not the other at the end.
    pub released_mismatch: usize,
    /// First frame whose released sets differ, if any.
    pub first_mismatch_frame: Option<u64>,
    /// Whether the runs agree within tolerance.
    pub agree: bool,
}

/// Run `scene` for `frames` frames on both devices and compare frame by frame.
pub fn compare(scene_path: &Path, frames: u64, threads: Option<usize>) -> Result<Comparison> {
    let scene = load_scene(scene_path)?;
    let cpu = build_scene(&scene, scene_path, threads)?.solver;
    let gpu = build_scene(&scene, scene_path, threads)?.solver;
    let mut cpu = Body::place(cpu, DeviceChoice::Cpu, |_| {})?;
    let mut gpu = Body::place(gpu, DeviceChoice::Gpu, |_| {})?;
    let size = {
        let (lo, hi) = cpu.solver().mesh().rest_bounds();
        (hi - lo).length()
    };
    let mut worst = (0.0f32, 0u64);
    let mut first_mismatch = None;
    for f in 0..frames {
        cpu.step_frame()?;
        gpu.step_frame()?;
        let d = cpu
            .solver()
            .positions()
            .iter()
            .zip(gpu.solver().positions())
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        if d > worst.0 {
            worst = (d, f);
        }
        if first_mismatch.is_none() && cpu.solver().cut().live() != gpu.solver().cut().live() {
            first_mismatch = Some(f);
        }
    }
    let (a, b) = (cpu.solver().cut().live(), gpu.solver().cut().live());
    let mismatch = a.iter().zip(b).filter(|(x, y)| x != y).count();
    Ok(Comparison {
        scene: scene.name,
        frames,
        device: gpu.device(),
        mesh_size: size,
        max_position_difference: worst.0,
        worst_frame: worst.1,
        released_cpu: cpu.solver().cut().released_count(),
        released_gpu: gpu.solver().cut().released_count(),
        released_mismatch: mismatch,
        first_mismatch_frame: first_mismatch,
        agree: worst.0 <= POSITION_TOLERANCE * size && mismatch == 0,
    })
}

/// CLI entry: print the comparison (text or JSON); exit 1 when the runs disagree.
pub fn run(scene: &Path, frames: u64, threads: Option<usize>, json: bool) -> Result<()> {
    let c = compare(scene, frames, threads)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        println!("{} on cpu vs {} for {} frames", c.scene, c.device, c.frames);
        println!(
            "  max position difference {:.3e} m at frame {} ({:.2e} of the mesh size; tolerance {:.0e})",
            c.max_position_difference,
            c.worst_frame,
            c.max_position_difference / c.mesh_size,
            POSITION_TOLERANCE
        );
        println!(
            "  released: cpu {}, gpu {}, in one set only {}",
            c.released_cpu, c.released_gpu, c.released_mismatch
        );
    }
    if !c.agree {
        bail!("the GPU run departs from the CPU reference beyond tolerance");
    }
    Ok(())
}
