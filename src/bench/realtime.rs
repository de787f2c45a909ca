//! `incise bench realtime`: the default scene (config/intestine_pull.ron) at its own
//! substeps, as a trainee would run it — per-frame wall ms (median, p99) split into the
//! substeps, the release checks inside them, and the end-of-frame stress, guards and
//! release; frames per second; on the CPU or the GPU (issue 17, item 6).

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use incise_sim::xpbd::CpuKernel;
use serde::Serialize;

use crate::bench::soak::percentile;
use crate::sim_body::{Body, DeviceChoice};

/// The realtime figures of one device.
#[derive(Debug, Clone, Serialize)]
pub struct RealtimeResult {
    /// Scene file.
    pub scene: String,
    /// "cpu (N threads)" or the GPU adapter.
    pub device: String,
    /// The CPU projection kernel ("Lanes", "PortableLanes" or "Scalar"; the GPU ignores it).
    pub cpu_kernel: String,
    /// Tets.
    pub tets: usize,
    /// Substeps per frame (the scene's).
    pub substeps: u32,
    /// Frame length, s.
    pub frame_dt: f32,
    /// Frames timed (after 2 warm-up frames).
    pub frames: usize,
    /// Median wall ms per frame.
    pub frame_ms_median: f64,
    /// 99th-percentile wall ms per frame.
    pub frame_ms_p99: f64,
    /// Median ms of the substeps (prediction, projection, contact, velocities).
    pub substeps_ms_median: f64,
    /// Median ms of the release checks inside the substeps (stress + release).
    pub release_checks_ms_median: f64,
    /// Median ms of the end-of-frame stress, guards and release hand-over.
    pub stress_ms_median: f64,
    /// Frames per second of wall time at the median frame.
    pub frames_per_second: f64,
    /// Whether the median frame fits the scene's frame length in wall time.
    pub real_time: bool,
}

/// CPU threads (default: the scene's) and projection kernel (default: the scene's).
pub type CpuChoice = (Option<usize>, Option<CpuKernel>);

/// Interleaved runs per kernel of the `--markdown` table.
pub const MARKDOWN_RUNS: usize = 3;

/// Time `frames` frames of `scene` on `device` and print a table row, the JSON, or (with
/// `Markdown`) the three CPU kernels interleaved, [`MARKDOWN_RUNS`] runs each, as the
/// markdown table of docs/performance.md under its provenance line.
pub fn run(
    scene: &Path,
    device: DeviceChoice,
    cpu: CpuChoice,
    frames: u32,
    output: crate::bench::BenchOutput,
) -> Result<()> {
    use crate::bench::BenchOutput;
    if output == BenchOutput::Markdown {
        let kernels = match cpu.1 {
            Some(k) => vec![k],
            None => vec![
                CpuKernel::Scalar,
                CpuKernel::PortableLanes,
                CpuKernel::Lanes,
            ],
        };
        let mut runs: Vec<Vec<RealtimeResult>> = vec![Vec::new(); kernels.len()];
        for _ in 0..MARKDOWN_RUNS {
            for (k, kernel) in kernels.iter().enumerate() {
                runs[k].push(measure(scene, device, (cpu.0, Some(*kernel)), frames)?);
            }
        }
        print!("{}", markdown(&runs));
        return Ok(());
    }
    let r = measure(scene, device, cpu, frames)?;
    if output == BenchOutput::Json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        println!("{}", summary(&r));
    }
    Ok(())
}

/// One result as a line of text.
fn summary(r: &RealtimeResult) -> String {
    format!(
        "{} on {} ({} kernel): {} tets, {} substeps/frame: {:.1} ms/frame median ({:.1} p99) = {:.1} fps; \
         substeps {:.1} ms, release checks {:.1} ms, stress+guards {:.1} ms{}",
        r.scene,
        r.device,
        r.cpu_kernel,
        r.tets,
        r.substeps,
        r.frame_ms_median,
        r.frame_ms_p99,
        r.frames_per_second,
        r.substeps_ms_median,
        r.release_checks_ms_median,
        r.stress_ms_median,
        if r.real_time { " (real time)" } else { "" }
    )
}

/// The runs of each kernel (one inner list per kernel) as docs/performance.md's
/// realtime table: min and median over the runs of each run's median frame.
pub fn markdown(runs: &[Vec<RealtimeResult>]) -> String {
    let mut s = format!(
        "{}\n\n| scene | device | tets | substeps / frame | kernel | ms/frame min / median | fps (median) | ms per substep | release checks ms | stress + guards ms |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        crate::provenance::generated_by()
    );
    for rs in runs.iter().filter(|rs| !rs.is_empty()) {
        let mid = |f: &dyn Fn(&RealtimeResult) -> f64| {
            let mut v: Vec<f64> = rs.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            percentile(&v, 0.5)
        };
        let median = mid(&|r| r.frame_ms_median);
        let min = rs
            .iter()
            .map(|r| r.frame_ms_median)
            .fold(f64::INFINITY, f64::min);
        let r = &rs[0];
        s += &format!(
            "| {} | {} | {} | {} | {} | {:.1} / {:.1} | {:.1} | {:.2} | {:.1} | {:.2} |\n",
            r.scene,
            r.device,
            r.tets,
            r.substeps,
            r.cpu_kernel,
            min,
            median,
            1e3 / median,
            mid(&|r| r.substeps_ms_median) / r.substeps as f64,
            mid(&|r| r.release_checks_ms_median),
            mid(&|r| r.stress_ms_median),
        );
    }
    s
}

/// The measurement behind [`run`].
pub fn measure(
    scene_path: &Path,
    device: DeviceChoice,
    (threads, kernel): CpuChoice,
    frames: u32,
) -> Result<RealtimeResult> {
    let mut scene = crate::scene::load_scene(scene_path)?;
    if let Some(k) = kernel {
        scene.solver.cpu_kernel = k;
    }
    let built = crate::scene::build_scene(&scene, scene_path, threads)?;
    let cpu_kernel = format!("{:?}", built.solver.params().cpu_kernel);
    let (tets, substeps, frame_dt) = (
        built.solver.mesh().tet_count(),
        built.solver.params().substeps,
        built.solver.params().frame_dt,
    );
    let stroke = built.tool.as_ref().and_then(|t| t.stroke.clone());
    let mut body = Body::place(built.solver, device, |m| eprintln!("note: {m}"))
        .with_context(|| format!("{}: placing the body", scene_path.display()))?;
    let (mut frame, mut solve, mut checks, mut stress) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for f in 0..frames.max(1) as u64 + 2 {
        if let Some(s) = &stroke {
            body.move_tool(s.pose_at((f + 1) as f64 * frame_dt as f64));
        }
        let t = Instant::now();
        let st = body
            .step_frame()
            .with_context(|| format!("{}: frame {f}", scene_path.display()))?;
        if f >= 2 {
            frame.push(t.elapsed().as_secs_f64() * 1e3);
            solve.push(st.solve_ms - st.check_ms);
            checks.push(st.check_ms);
            stress.push(st.stress_ms);
        }
    }
    for v in [&mut frame, &mut solve, &mut checks, &mut stress] {
        v.sort_by(f64::total_cmp);
    }
    let median = |v: &[f64]| percentile(v, 0.5);
    let frame_ms_median = median(&frame);
    Ok(RealtimeResult {
        scene: scene_path.display().to_string(),
        device: body.device(),
        cpu_kernel,
        tets,
        substeps,
        frame_dt,
        frames: frame.len(),
        frame_ms_median,
        frame_ms_p99: percentile(&frame, 0.99),
        substeps_ms_median: median(&solve),
        release_checks_ms_median: median(&checks),
        stress_ms_median: median(&stress),
        frames_per_second: 1e3 / frame_ms_median,
        real_time: frame_ms_median <= frame_dt as f64 * 1e3,
    })
}
