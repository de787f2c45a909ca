//! `incise bench realtime`: the default scene (config/intestine_pull.ron) on its own
//! scheme (the implicit scheme; XPBD's substeps for an XPBD scene), as a trainee would run
//! it — per-frame wall ms (median, p99) split into the solve (substeps or implicit steps),
//! the release checks inside them, and the end-of-frame stress, guards and release; frames
//! per second; on the CPU or the GPU (issue 17, item 6). Per kernel also what a sweep
//! costs against its arithmetic (issue 35, item 5): ms per sweep on one thread and on all,
//! their ratio, GFLOP/s from the counted flops of a projection
//! ([`incise_sim::xpbd::projection_flops`]) against the machine's peak
//! ([`crate::bench::peak`]), and the parallel passes (GPU: dispatches) of a frame.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use incise_sim::implicit::Scheme;
use incise_sim::xpbd::{CpuKernel, CpuSweep, NODE_FLOPS_PER_SUBSTEP, projection_flops};
use serde::Serialize;

use crate::quantile::percentile;
use crate::sim_body::{Body, DeviceChoice};

/// The realtime figures of one device.
#[derive(Debug, Clone, Serialize)]
pub struct RealtimeResult {
    /// Scene file.
    pub scene: String,
    /// "cpu (N threads)" or the GPU adapter.
    pub device: String,
    /// The CPU projection kernel ("Lanes", "Avx2Lanes", "PortableLanes" or "Scalar"; the
    /// GPU ignores it), with ", Blocks" for the partitioned sweep; "Newton" for the
    /// implicit scheme.
    pub cpu_kernel: String,
    /// The time integrator: "XPBD" or "Newton".
    pub scheme: String,
    /// CPU solver threads (0 on the GPU).
    pub threads: usize,
    /// Tets.
    pub tets: usize,
    /// Nodes.
    pub nodes: usize,
    /// Substeps (XPBD) or implicit steps (Newton) per frame.
    pub substeps: u32,
    /// Frame length, s.
    pub frame_dt: f32,
    /// Frames timed (after the warm-up frames).
    pub frames: usize,
    /// Frames stepped before the timed ones and not timed ([`WARM_UP_FRAMES`]).
    pub warm_up_frames: u64,
    /// Frames the scene runs for its duration (the timed ones are frames
    /// `warm_up_frames` to `warm_up_frames + frames − 1` of them).
    pub scene_frames: u64,
    /// Median wall ms per frame.
    pub frame_ms_median: f64,
    /// 95th-percentile wall ms per frame.
    pub frame_ms_p95: f64,
    /// 99th-percentile wall ms per frame.
    pub frame_ms_p99: f64,
    /// Median ms of the substeps (prediction, projection, contact, velocities).
    pub substeps_ms_median: f64,
    /// Median ms of the release checks inside the substeps (stress + release).
    pub release_checks_ms_median: f64,
    /// Median ms of the end-of-frame stress, guards and release hand-over.
    pub stress_ms_median: f64,
    /// Median ms of one sweep (an XPBD substep: prediction, one projection of every
    /// tet, contact, velocities).
    pub sweep_ms_median: f64,
    /// Flops of one sweep: tets × the counted flops of a projection + nodes × the
    /// prediction's and velocity update's.
    pub flops_per_sweep: f64,
    /// GFLOP/s achieved at the median sweep.
    pub gflops: f64,
    /// Median parallel passes of a frame (CPU: colour and stress passes, each a
    /// synchronisation of the threads; GPU: compute dispatches).
    pub passes_per_frame: u32,
    /// Frames per second of wall time at the median frame.
    pub frames_per_second: f64,
    /// Mean wall ms per frame over the timed frames.
    pub frame_ms_mean: f64,
    /// Frames per second the timed frames kept up, `1000 / frame_ms_mean`: what a
    /// session sustains where some frames (a tear, an incision) cost more than the median.
    pub frames_per_second_sustained: f64,
    /// Whether the median frame fits the scene's frame length in wall time.
    pub real_time: bool,
}

/// Frames each run steps before it starts timing (first-frame allocation, thread start).
pub const WARM_UP_FRAMES: u64 = 2;

/// CPU threads, projection kernel and sweep order (each by default the scene's).
pub type CpuChoice = (Option<usize>, Option<CpuKernel>, Option<CpuSweep>);

/// Interleaved runs per kernel of the `--markdown` table.
pub const MARKDOWN_RUNS: usize = 3;

/// Time `frames` frames of `scene` on `device` and print a table row, the JSON, or (with
/// `Markdown`) the XPBD kernels and the implicit scheme (the scene's Newton settings, or
/// the defaults) interleaved, [`MARKDOWN_RUNS`] runs each, as the markdown table of
/// docs/performance.md under its provenance line; on the CPU the implicit scheme also over
/// the whole scene (its cost moves from frame to frame: settling, pulling, tearing, torn),
/// the figure a trainee's session has.
pub fn run(
    scene: &Path,
    device: DeviceChoice,
    cpu: CpuChoice,
    frames: u32,
    output: crate::bench::BenchOutput,
) -> Result<()> {
    use crate::bench::BenchOutput;
    if output == BenchOutput::Markdown {
        let xpbd = Some(Scheme::Xpbd);
        let on_xpbd = |k: CpuKernel, s: Option<CpuSweep>| (k, s, xpbd, Some(frames));
        let mut kernels = match cpu.1 {
            Some(k) => vec![on_xpbd(k, cpu.2)],
            None => vec![
                on_xpbd(CpuKernel::Scalar, Some(CpuSweep::Coloured)),
                on_xpbd(CpuKernel::PortableLanes, Some(CpuSweep::Coloured)),
                on_xpbd(CpuKernel::Lanes, Some(CpuSweep::Coloured)),
                on_xpbd(CpuKernel::Lanes, Some(CpuSweep::Blocks)),
                on_xpbd(CpuKernel::Avx2Lanes, Some(CpuSweep::Blocks)),
            ],
        };
        let on_cpu = device != DeviceChoice::Gpu;
        if on_cpu {
            let newton = Some(newton_of(scene)?);
            kernels.push((CpuKernel::Lanes, None, newton, Some(frames)));
            kernels.push((CpuKernel::Lanes, None, newton, None));
        }
        let mut runs: Vec<KernelRuns> = vec![KernelRuns::default(); kernels.len()];
        for _ in 0..MARKDOWN_RUNS {
            for (k, &(kernel, sweep, scheme, frames)) in kernels.iter().enumerate() {
                let choice = |threads| (threads, Some(kernel), sweep);
                runs[k].all.push(measure_scheme(
                    scene,
                    device,
                    choice(cpu.0),
                    scheme,
                    frames,
                )?);
                if on_cpu && scheme == xpbd {
                    let one = measure_scheme(scene, device, choice(Some(1)), xpbd, frames)?;
                    runs[k].one.push(one);
                }
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

/// The frames a run timed, as "first–last" of the scene's frames.
fn timed_frames(r: &RealtimeResult) -> String {
    let first = r.warm_up_frames;
    format!("{first}–{}", first + r.frames as u64 - 1)
}

/// One result as a line of text.
fn summary(r: &RealtimeResult) -> String {
    format!(
        "{} on {} ({} kernel): {} tets, {} substeps/frame, frames {} of {}: {:.1} ms/frame median ({:.1} p99) = {:.1} fps; \
         substeps {:.1} ms, release checks {:.1} ms, stress+guards {:.1} ms; \
         {:.3} ms a sweep, {:.2} GFLOP/s, {} passes a frame{}",
        r.scene,
        r.device,
        r.cpu_kernel,
        r.tets,
        r.substeps,
        timed_frames(r),
        r.scene_frames,
        r.frame_ms_median,
        r.frame_ms_p99,
        r.frames_per_second,
        r.substeps_ms_median,
        r.release_checks_ms_median,
        r.stress_ms_median,
        r.sweep_ms_median,
        r.gflops,
        r.passes_per_frame,
        if r.real_time { " (real time)" } else { "" }
    )
}

/// The interleaved runs of one kernel: on all threads (or the GPU) and on one thread.
#[derive(Debug, Clone, Default)]
pub struct KernelRuns {
    /// Runs on the asked threads (default all cores), or on the GPU.
    pub all: Vec<RealtimeResult>,
    /// Runs on one thread (none on the GPU).
    pub one: Vec<RealtimeResult>,
}

/// Median over `rs` of `f`.
fn median_of(rs: &[RealtimeResult], f: impl Fn(&RealtimeResult) -> f64) -> f64 {
    let mut v: Vec<f64> = rs.iter().map(f).collect();
    v.sort_by(f64::total_cmp);
    percentile(&v, 0.5)
}

/// The runs of each kernel as docs/performance.md's realtime table: min and median over
/// the runs of each run's median frame; the sweep on one thread and on all, their ratio,
/// GFLOP/s and the share of the machine's peak on all threads; the frame's cost in fine
/// sweeps (its median ms over the ms of one coloured `Lanes` XPBD sweep of the same mesh on
/// all threads, measured in the same run: issue 31's yardstick); which of the scene's
/// frames were timed ("whole scene" in the kernel cell where that is all of them after the
/// warm-up), the median over the runs of each run's 95th-percentile frame and of the
/// frames a second it sustained (its frames over their summed time); then how the peak and
/// the flops were counted.
pub fn markdown(runs: &[KernelRuns]) -> String {
    let mut s = format!(
        "{}\n\n| scene | device | tets | substeps / frame | kernel | ms/frame min / median | fps (median) | ms per sweep, 1 thread / all | 1 → all threads | GFLOP/s | % of peak | passes / frame | release checks ms | stress + guards ms | fine sweeps / frame | frames timed | ms/frame p95 | fps sustained |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        crate::provenance::generated_by()
    );
    // The peak of the threads the CPU rows ran on (none for the GPU).
    let peak = runs
        .iter()
        .find_map(|k| k.all.first().filter(|r| r.threads > 0))
        .and_then(|r| crate::bench::peak::peak(r.threads));
    let unit = runs
        .iter()
        .find(|k| k.all.first().is_some_and(|r| r.cpu_kernel == "Lanes"))
        .map(|k| median_of(&k.all, |r| r.sweep_ms_median));
    for k in runs.iter().filter(|k| !k.all.is_empty()) {
        let rs = &k.all;
        let median = median_of(rs, |r| r.frame_ms_median);
        let min = rs
            .iter()
            .map(|r| r.frame_ms_median)
            .fold(f64::INFINITY, f64::min);
        let r = &rs[0];
        let sweep = median_of(rs, |r| r.sweep_ms_median);
        let gflops = median_of(rs, |r| r.gflops);
        let (one, scaling) = match k.one.is_empty() {
            true => ("–".to_string(), "–".to_string()),
            false => {
                let one = median_of(&k.one, |r| r.sweep_ms_median);
                (format!("{one:.3}"), format!("{:.2}×", one / sweep))
            }
        };
        let share = peak.as_ref().map_or("–".to_string(), |p| {
            format!("{:.1} %", 100.0 * gflops / p.gflops)
        });
        // A Newton frame has no sweeps: its sweep, flops and peak cells say so.
        let (sweep, gflops, share) = if r.scheme == Scheme::Xpbd.name() {
            (format!("{sweep:.3}"), format!("{gflops:.2}"), share)
        } else {
            ("–".into(), "–".into(), "–".into())
        };
        let whole = r.warm_up_frames + r.frames as u64 >= r.scene_frames;
        let kernel = match whole {
            true => format!("{}, whole scene", r.cpu_kernel),
            false => r.cpu_kernel.clone(),
        };
        s += &format!(
            "| {} | {} | {} | {} | {kernel} | {min:.1} / {median:.1} | {:.1} | {one} / {sweep} | {scaling} | {gflops} | {share} | {} | {:.1} | {:.2} | {:.1} | {} | {:.1} | {:.1} |\n",
            r.scene,
            r.device,
            r.tets,
            r.substeps,
            1e3 / median,
            median_of(rs, |r| r.passes_per_frame as f64),
            median_of(rs, |r| r.release_checks_ms_median),
            median_of(rs, |r| r.stress_ms_median),
            median / unit.unwrap_or(median_of(rs, |r| r.sweep_ms_median)),
            timed_frames(r),
            median_of(rs, |r| r.frame_ms_p95),
            median_of(rs, |r| r.frames_per_second_sustained),
        );
    }
    s += &format!(
        "\nFlops of a sweep: {} per tet projection (counted: `incise_sim::xpbd::projection_flops`) \
         + {NODE_FLOPS_PER_SUBSTEP} per node. Peak: {}.\n",
        projection_flops(),
        peak.map_or("not known on this system".to_string(), |p| format!(
            "{} = {:.0} GFLOP/s (`cpu MHz` of /proc/cpuinfo, two FMA pipes a core)",
            p.how, p.gflops
        ))
    );
    s
}

/// The implicit scheme the table compares: the scene's own Newton settings, or the
/// defaults for an XPBD scene.
fn newton_of(scene: &Path) -> Result<Scheme> {
    let own = crate::scene::load_scene(scene)?.solver.scheme;
    Ok(Scheme::Newton(own.newton_or_default()))
}

/// The measurement behind [`run`], with the scene's own scheme.
pub fn measure(
    scene_path: &Path,
    device: DeviceChoice,
    cpu: CpuChoice,
    frames: u32,
) -> Result<RealtimeResult> {
    measure_scheme(scene_path, device, cpu, None, Some(frames))
}

/// [`measure`] with the scheme replaced when `scheme` is given, over `frames` frames after
/// the warm-up (`None`: all the scene's).
fn measure_scheme(
    scene_path: &Path,
    device: DeviceChoice,
    (threads, kernel, sweep): CpuChoice,
    scheme: Option<Scheme>,
    frames: Option<u32>,
) -> Result<RealtimeResult> {
    let mut scene = crate::scene::load_scene(scene_path)?;
    let scene_frames = scene.frame_count(scene.solver.frame_dt as f64);
    // `None`: the whole scene, every frame after the warm-up ones.
    let frames = frames.map_or(scene_frames.saturating_sub(WARM_UP_FRAMES), u64::from);
    if let Some(s) = scheme {
        scene.solver.scheme = s;
    }
    if let Some(k) = kernel {
        scene.solver.cpu_kernel = k;
    }
    if let Some(s) = sweep {
        scene.solver.cpu_sweep = s;
    }
    let built = crate::scene::build_scene(&scene, scene_path, threads)?;
    let params = built.solver.params();
    let cpu_kernel = match (params.scheme, params.cpu_sweep) {
        (Scheme::Newton(_), _) => params.scheme.name().to_string(),
        (Scheme::Xpbd, CpuSweep::Coloured) => format!("{:?}", params.cpu_kernel),
        (Scheme::Xpbd, CpuSweep::Blocks) => format!("{:?}, Blocks", params.cpu_kernel),
    };
    let scheme = params.scheme.name().to_string();
    let cpu_threads = match params.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    let nodes = built.solver.mesh().node_count();
    let (tets, substeps, frame_dt) = (
        built.solver.mesh().tet_count(),
        built.solver.params().steps(),
        built.solver.params().frame_dt,
    );
    let stroke = built.tool.as_ref().and_then(|t| t.stroke.clone());
    let mut body = Body::place(built.solver, device, |m| eprintln!("note: {m}"))
        .with_context(|| format!("{}: placing the body", scene_path.display()))?;
    let (mut frame, mut solve, mut checks, mut stress, mut passes) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for f in 0..frames.max(1) + WARM_UP_FRAMES {
        if let Some(s) = &stroke {
            body.move_tool(s.pose_at((f + 1) as f64 * frame_dt as f64));
        }
        let t = Instant::now();
        let st = body
            .step_frame()
            .with_context(|| format!("{}: frame {f}", scene_path.display()))?;
        if f >= WARM_UP_FRAMES {
            frame.push(t.elapsed().as_secs_f64() * 1e3);
            solve.push(st.solve_ms - st.check_ms);
            checks.push(st.check_ms);
            stress.push(st.stress_ms);
            passes.push(st.passes as f64);
        }
    }
    for v in [
        &mut frame,
        &mut solve,
        &mut checks,
        &mut stress,
        &mut passes,
    ] {
        v.sort_by(f64::total_cmp);
    }
    let median = |v: &[f64]| percentile(v, 0.5);
    let frame_ms_median = median(&frame);
    let frame_ms_mean = frame.iter().sum::<f64>() / frame.len() as f64;
    let sweep_ms_median = median(&solve) / substeps as f64;
    let flops_per_sweep =
        (tets as u64 * projection_flops() + nodes as u64 * NODE_FLOPS_PER_SUBSTEP) as f64;
    let device_name = body.device();
    Ok(RealtimeResult {
        scene: scene_path.display().to_string(),
        threads: if device_name.starts_with("cpu") {
            cpu_threads
        } else {
            0
        },
        device: device_name,
        cpu_kernel,
        scheme,
        tets,
        nodes,
        substeps,
        frame_dt,
        frames: frame.len(),
        warm_up_frames: WARM_UP_FRAMES,
        scene_frames,
        frame_ms_median,
        frame_ms_p95: percentile(&frame, 0.95),
        frame_ms_p99: percentile(&frame, 0.99),
        substeps_ms_median: median(&solve),
        release_checks_ms_median: median(&checks),
        stress_ms_median: median(&stress),
        sweep_ms_median,
        flops_per_sweep,
        gflops: flops_per_sweep / (sweep_ms_median * 1e6),
        passes_per_frame: median(&passes) as u32,
        frames_per_second: 1e3 / frame_ms_median,
        frame_ms_mean,
        frames_per_second_sustained: 1e3 / frame_ms_mean,
        real_time: frame_ms_median <= frame_dt as f64 * 1e3,
    })
}
