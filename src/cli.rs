//! Command-line interface definition (clap).

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand, ValueEnum};

use crate::bench::BenchCase;
use crate::mesh_cmd::GenKind;
use crate::pictures::screenshots::{ImageSize, OverlayArg};
use crate::preview::PreviewOptions;
use crate::run::RunOptions;
use crate::scene::built_in::resolve;
use crate::sim_body::DeviceChoice;
use crate::xr::XrOptions;
use crate::xr::sim_mode::SimChoice;

/// The scene `incise run` and `incise preview` open when none is named.
pub const DEFAULT_SCENE: &str = "config/intestine_pull.ron";

/// The scene `incise xr` opens when none is named.
pub const XR_SCENE: &str = "config/plate_cut.ron";

/// incise: mixed-reality surgical cutting trainer (headless runner, mesh tools, benchmarks).
#[derive(Debug, Parser)]
#[command(name = "incise", version, about)]
pub struct Cli {
    /// What to do (none: the preview of the default scene, or a headless run of it
    /// when there is no display).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene headless: report.json, .vtu snapshots and a .pvd collection.
    Run(RunArgs),
    /// Open the desktop preview: the scene in a window with a control panel.
    Preview(PreviewArgs),
    /// The scene on a tray in the room of an OpenXR headset (Meta Quest 3 over Link,
    /// WiVRn/Monado), cut with the right controller; exits 2 when no runtime or headset
    /// is usable. `--simulated-headset` runs the same frame loop on a scripted headset.
    Xr(XrArgs),
    /// Render one frame of a scene offscreen to a PNG (no window needed).
    Render {
        /// Scene file (RON) or a built-in scene's name.
        #[arg(value_parser = config_file)]
        scene: PathBuf,
        /// Frames to simulate before rendering (0: the rest state).
        #[arg(long, default_value_t = 0)]
        frame: u64,
        /// Output PNG.
        out: PathBuf,
        /// Image size, WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720")]
        size: ImageSize,
        /// Overlays to draw (repeat or comma-separate).
        #[arg(long, value_enum, value_delimiter = ',')]
        overlay: Vec<OverlayArg>,
        /// Where the solver runs (auto: on the render device's GPU).
        #[arg(long, value_enum, default_value_t = DeviceChoice::Auto)]
        device: DeviceChoice,
    },
    /// Run a scene on the CPU and the GPU side by side; exit 1 if they disagree.
    Compare {
        /// Scene file (RON) or a built-in scene's name.
        #[arg(value_parser = config_file)]
        scene: PathBuf,
        /// Frames to compare (default: the scene's duration).
        #[arg(long)]
        frames: Option<u64>,
        /// CPU solver threads (0: all cores; at most one per core).
        #[arg(long)]
        threads: Option<usize>,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Mesh tools.
    Mesh {
        /// Which tool.
        #[command(subcommand)]
        command: MeshCommand,
    },
    /// Time the solver (10 substeps per frame) on the plate and the 34k-tet intestine, or
    /// with `render` the offscreen renderer (1080p and Quest 3 stereo).
    Bench {
        /// What to time.
        #[arg(value_enum, default_value_t = BenchTarget::Solver)]
        target: BenchTarget,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Print the table as the markdown rows of docs/performance.md, under a line giving
        /// the command, machine (CPU model, cores), UTC date and load average (`realtime`:
        /// the CPU kernels and sweeps interleaved, three runs each, on one thread and on
        /// all, unless `--cpu-kernel` names one).
        #[arg(long, conflicts_with = "json")]
        markdown: bool,
        /// Frames to time per case (after 2 warm-up frames; the solver target interleaves
        /// its variants frame by frame).
        #[arg(long, default_value_t = 10)]
        frames: u32,
        /// Which cases to run.
        #[arg(long, value_enum, default_value_t = BenchCase::All)]
        case: BenchCase,
        /// Where the solver runs (cpu: serial and all threads).
        #[arg(long, value_enum, default_value_t = DeviceChoice::Cpu)]
        device: DeviceChoice,
        /// Add the intestine scaling series (≈140k, 550k, 1.1M tets).
        #[arg(long)]
        scaling: bool,
        /// Scene of the `realtime` and `scene` targets.
        #[arg(long, default_value = DEFAULT_SCENE, value_parser = config_file)]
        scene: PathBuf,
        /// CPU solver threads of the `realtime` target (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// CPU projection kernel of the `realtime` target (default: the scene's).
        #[arg(long, value_enum)]
        cpu_kernel: Option<KernelChoice>,
        /// CPU sweep order of the `realtime` target (default: the scene's).
        #[arg(long, value_enum)]
        cpu_sweep: Option<SweepChoice>,
    },
    /// Endurance run: cut a scalpel scene, reset, cut again for a wall-clock duration;
    /// fails (exit 1) if memory grows > 5 %, file descriptors leak or a cut differs.
    Soak {
        /// Scene file with a tool and a stroke, e.g. config/plate_cut.ron.
        #[arg(value_parser = config_file)]
        scene: PathBuf,
        /// Wall-clock duration in seconds (at least three cuts are made).
        #[arg(long, default_value_t = 3600.0)]
        seconds: f64,
        /// Where the solver runs.
        #[arg(long, value_enum, default_value_t = DeviceChoice::Auto)]
        device: DeviceChoice,
        /// Output folder for soak.json.
        #[arg(long, default_value = "out/soak")]
        out: PathBuf,
        /// Also print the result as a row of docs/reliability.md's soak table, under a
        /// line giving the command, machine (CPU model, cores), UTC date and load average.
        #[arg(long)]
        markdown: bool,
    },
    /// Score a stroke on a training exercise: runs the exercise's scene with the stroke
    /// driving the scalpel, writes DIR/result.json and DIR/report.html and appends the
    /// attempt to the results history.
    Exercise {
        /// Exercise file (RON), e.g. config/exercises/slab_depth.ron.
        #[arg(value_parser = config_file)]
        exercise: PathBuf,
        /// Stroke file (RON timed poses: recorded with `incise run --record-stroke`, or
        /// scripted).
        #[arg(long, required_unless_present = "reference_stroke", value_parser = config_file)]
        stroke: Option<PathBuf>,
        /// Instead of scoring, write the exercise's reference stroke (the scene's scalpel
        /// along the plan at the target depth, handle raised `--tilt`) to this file.
        #[arg(long, conflicts_with = "stroke")]
        reference_stroke: Option<PathBuf>,
        /// Reference stroke: angle of the blade's spine above the surface, degrees.
        #[arg(long, default_value_t = 30.0)]
        tilt: f32,
        /// Output folder.
        #[arg(long, default_value = "out/exercise")]
        out: PathBuf,
        /// Where the solver runs (auto: the GPU when an adapter exists, else the CPU).
        #[arg(long, value_enum, default_value_t = DeviceChoice::Auto)]
        device: DeviceChoice,
        /// Results history the attempt is appended to (one JSON line per attempt).
        #[arg(long, default_value = "results/history.jsonl")]
        history: PathBuf,
        /// No progress output.
        #[arg(long)]
        quiet: bool,
    },
    /// List the built-in scenes and exercises (each runs by name from any directory, e.g.
    /// `incise run intestine_pull`), or export the built-in config tree to edit.
    Scenes {
        /// What to do (none: list them).
        #[command(subcommand)]
        action: Option<ScenesAction>,
    },
    /// What this machine offers the trainer: GPU adapters (and which one `--device auto`
    /// picks), Vulkan, the OpenXR loader and runtime, a headset, a display for the
    /// preview; each ok or missing with the fix. Exits 1 when the headset path cannot work.
    Doctor,
    /// Print the results history as a table, oldest attempt first.
    Results {
        /// Results history file.
        #[arg(long, default_value = "results/history.jsonl")]
        history: PathBuf,
    },
    /// Reproducible experiments that write the CSV tables and PNG figures of docs/experiments/.
    Experiment {
        /// Which experiment.
        #[command(subcommand)]
        command: ExperimentCommand,
    },
}

/// Experiment subcommands.
#[derive(Debug, Subcommand)]
pub enum ExperimentCommand {
    /// Three-element rheology (PHYSICS.md §3): creep vs closed form, press-and-release of a
    /// block with every preset, hold-time sweep, force-dependent damper under gravity.
    Rheology {
        /// Output folder for the CSV tables, PNG figures and summary.txt.
        #[arg(long)]
        out: PathBuf,
        /// Rheological preset file.
        #[arg(long, default_value = "config/rheology.ron")]
        presets: PathBuf,
        /// Quick version (seconds, not minutes): every part on the coarse 40 × 40 × 20 cm
        /// block of 10 cm cells, hold times 0.1 and 1 s, 2 s of sag. The figures in
        /// docs/experiments/rheology/ come from the full version (without --quick).
        #[arg(long)]
        quick: bool,
    },
    /// Nakao 2003 plate (PHYSICS.md §2.6): the same straight cut at tension 0–6 %, adaptive
    /// and non-adaptive; writes table.md/.csv, results.json and PNG figures.
    NakaoPlate {
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Quick version (seconds, not minutes): a 4 cm cut instead of 14 cm at 0 and 4 %
        /// tension, adaptive and non-adaptive, 0.2 s for the wound to open. The figures in
        /// docs/experiments/nakao/ come from the full version (without --quick).
        #[arg(long)]
        quick: bool,
    },
    /// Nakao 2003 chest (PHYSICS.md §2.6, Figs. 15–17): an incision along the sternum of a
    /// torso-like chest (the paper's 17,582 nodes) at levels 4, 6 and with the refresh-rate
    /// manager at 5.6 ms; prints the paper's tables beside ours, writes table.md,
    /// loops.csv and results.json.
    NakaoChest {
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// 10 ms loops per case (at least 20).
        #[arg(long, default_value_t = 120)]
        loops: usize,
    },
    /// The scene figures the documents quote (frames, tets, released tets, peak tool
    /// force; CPU solver), as a markdown table; `--update FILE` rewrites that table
    /// between its markers in FILE (docs/performance.md).
    SceneFigures {
        /// Scenes to run to their end.
        #[arg(default_values = ["config/plate_cut.ron", "config/slab_layer.ron", "config/intestine_incision.ron"])]
        scenes: Vec<PathBuf>,
        /// Rewrite the generated table in this document.
        #[arg(long)]
        update: Option<PathBuf>,
    },
    /// The substep budget of XPBD scenes and whether it is converged: each scene as
    /// scripted over its whole duration at the fewest substeps the stability bound allows,
    /// at its own count and at a reference (≥ 375), with the stress, displacement and
    /// volume errors, released tets and first release against the reference; `--update
    /// FILE` rewrites that table between its markers (docs/physics-notes.md).
    Substeps {
        /// Scenes to measure.
        #[arg(default_values = ["config/plate_cut.ron", "config/slab_layer.ron", "config/bowel_cantilever.ron", "config/intestine_pull.ron"])]
        scenes: Vec<PathBuf>,
        /// Frames per run (default: each scene's whole duration).
        #[arg(long)]
        frames: Option<u32>,
        /// Rewrite the generated table in this document.
        #[arg(long)]
        update: Option<PathBuf>,
    },
    /// Loop times of the mass-spring cutter on a chest-scale slab (18.5k nodes, 72k tets):
    /// levels 4 and 6, the whole mesh, the refresh-rate manager and the blade advances.
    NakaoBench {
        /// Loops per case.
        #[arg(long, default_value_t = 400)]
        loops: usize,
        /// Time budget per loop of the refresh-rate manager case, ms.
        #[arg(long, default_value_t = 0.1)]
        budget_ms: f64,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
    },
}

/// Mesh subcommands.
#[derive(Debug, Subcommand)]
pub enum MeshCommand {
    /// Load a mesh and print counts and quality; exits 1 on a bad file.
    Check {
        /// .node/.ele, .msh, .vtk or .vtu file.
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Generate a procedural mesh as TetGen .node/.ele plus an .obj skin.
    Gen {
        /// Which mesh.
        #[arg(value_enum)]
        kind: GenKind,
        /// Output base path (writes BASE.node, BASE.ele, BASE.obj).
        #[arg(long)]
        out: PathBuf,
    },
}

/// Which CPU kernel projects the tets (`incise bench realtime --cpu-kernel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum KernelChoice {
    /// Eight tets at once in SIMD lanes, AVX-512 or AVX2 where the CPU has it (the default).
    Lanes,
    /// The same lanes, never wider than AVX2 (what an AVX2-only CPU runs).
    Avx2Lanes,
    /// The same lanes at the build's own instruction set (no AVX2 detection).
    PortableLanes,
    /// One tet at a time (the reference).
    Scalar,
}

impl From<KernelChoice> for incise_sim::xpbd::CpuKernel {
    fn from(k: KernelChoice) -> Self {
        match k {
            KernelChoice::Lanes => incise_sim::xpbd::CpuKernel::Lanes,
            KernelChoice::Avx2Lanes => incise_sim::xpbd::CpuKernel::Avx2Lanes,
            KernelChoice::PortableLanes => incise_sim::xpbd::CpuKernel::PortableLanes,
            KernelChoice::Scalar => incise_sim::xpbd::CpuKernel::Scalar,
        }
    }
}

/// In which order the CPU sweeps the tets (`incise bench realtime --cpu-sweep`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SweepChoice {
    /// One pass per colour over the whole mesh (the reference order).
    Coloured,
    /// Fixed slabs of the mesh, each colour after colour by one task: four
    /// synchronisations a sweep.
    Blocks,
}

impl From<SweepChoice> for incise_sim::xpbd::CpuSweep {
    fn from(k: SweepChoice) -> Self {
        match k {
            SweepChoice::Coloured => incise_sim::xpbd::CpuSweep::Coloured,
            SweepChoice::Blocks => incise_sim::xpbd::CpuSweep::Blocks,
        }
    }
}

/// What `incise bench` times.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BenchTarget {
    /// The XPBD solver.
    Solver,
    /// The renderer alone, offscreen.
    Render,
    /// The default scene on its own scheme: ms per frame split into the solve (XPBD
    /// substeps or implicit steps), release checks and stress; frames per second
    /// (`--scene` for another scene; `--markdown`: XPBD's kernels beside the implicit scheme).
    Realtime,
    /// The `--scene` of any method through its body's script: ms per frame, nodes and
    /// tets, and a Nakao body's localisation levels and loop split (`--frames` frames).
    Scene,
}

/// A loop rate in Hz: finite, above 0 and at most 100 kHz.
fn positive_rate(s: &str) -> Result<f64, String> {
    let hz: f64 = s
        .parse()
        .map_err(|_| format!("`{s}` is not a number of Hz"))?;
    if hz.is_finite() && hz > 0.0 && hz <= 100_000.0 {
        Ok(hz)
    } else {
        Err(format!("must be a rate in (0, 100000] Hz, got {s}"))
    }
}

/// `incise run`'s arguments.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Scene file (RON) or a built-in scene's name, e.g. config/intestine_pull.ron.
    #[arg(value_parser = config_file)]
    pub scene: PathBuf,
    /// Frames to simulate (default: the scene's duration at its frame rate).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Write a .vtu snapshot every K frames (0: none).
    #[arg(long, default_value_t = 10)]
    pub vtu_every: u64,
    /// Solver threads (0: all cores, at most one per core; default: the scene's setting).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// Where the solver runs (auto: the GPU when an adapter exists, else the CPU).
    #[arg(long, value_enum, default_value_t = DeviceChoice::Auto)]
    pub device: DeviceChoice,
    /// Write DIR/frame_NNNNN.png every K frames, rendered offscreen (0: none).
    #[arg(long, default_value_t = 0)]
    pub screenshot_every: u64,
    /// Size of those screenshots, WIDTHxHEIGHT.
    #[arg(long, default_value = "960x540")]
    pub screenshot_size: ImageSize,
    /// Mass-spring scenes: run the localised loop on its own thread at this rate, Hz
    /// (e.g. 1000 for a haptic device), with the tool on the scene's blade stroke; the
    /// report loop runs at the scene's frame rate in real time.
    #[arg(long, value_parser = positive_rate)]
    pub haptic_rate: Option<f64>,
    /// Drive the scene's scalpel with this stroke file (RON timed poses) instead.
    #[arg(long)]
    pub stroke: Option<PathBuf>,
    /// Record the scalpel's pose every frame to this stroke file.
    #[arg(long)]
    pub record_stroke: Option<PathBuf>,
    /// Mass-spring scenes: replay the free nodes of each localised frame of the run that
    /// wrote this report.json instead of choosing them (a `Budget` scene's manager
    /// chooses by wall time: the replay reproduces that run bit for bit).
    #[arg(long, value_name = "REPORT")]
    pub replay_localisation: Option<PathBuf>,
    /// Testing aid: destroy the GPU device just before frame N (the run must go on
    /// on the CPU with a warning in report.json).
    #[arg(long, value_name = "N")]
    pub inject_gpu_loss_at: Option<u64>,
    /// Testing aid: give a node a NaN velocity just before frame N (the run must stop
    /// with the frame and tet named, the frame rolled back, the output kept).
    #[arg(long, value_name = "N")]
    pub inject_nan_at: Option<u64>,
}

/// `incise preview`'s arguments.
#[derive(Debug, Clone, clap::Args)]
pub struct PreviewArgs {
    /// Scene file (RON) or a built-in scene's name.
    #[arg(default_value = DEFAULT_SCENE, value_parser = config_file)]
    pub scene: PathBuf,
    /// Render this many frames, then exit.
    #[arg(long)]
    pub frames: Option<u64>,
    /// Save the window's last frame to this PNG on exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Where the solver runs (auto: a hardware GPU if there is one, else the CPU).
    #[arg(long, value_enum, default_value_t = DeviceChoice::Auto)]
    pub device: DeviceChoice,
    /// Window size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x800")]
    pub size: ImageSize,
    /// Open this exercise (config/exercises/*.ron): its scene, the planned incision
    /// drawn on the tissue, attempts scored and saved to out/exercises/ and
    /// results/history.jsonl.
    #[arg(long, conflicts_with = "scene", value_parser = config_file)]
    pub exercise: Option<PathBuf>,
}

/// `incise xr`'s arguments.
#[derive(Debug, Clone, clap::Args)]
pub struct XrArgs {
    /// Scene file (RON) or a built-in scene's name.
    #[arg(default_value = XR_SCENE, value_parser = config_file)]
    pub scene: PathBuf,
    /// Run without a runtime on this headset script (RON: head, controller and
    /// button tracks), rendering both eyes offscreen.
    #[arg(long, value_parser = config_file)]
    pub simulated_headset: Option<PathBuf>,
    /// Output folder: frames.csv (frame times), xr_report.json, stroke.ron, eye PNGs.
    #[arg(long, default_value = "out/xr")]
    pub out: PathBuf,
    /// Also write the recorded scalpel stroke here (replay: `incise run --stroke`).
    #[arg(long)]
    pub record_stroke: Option<PathBuf>,
    /// Stop after this many display frames.
    #[arg(long)]
    pub frames: Option<u64>,
    /// Where the solver runs (auto: the headset's GPU; the CPU for a simulated one).
    #[arg(long, value_enum, default_value_t = DeviceChoice::Auto)]
    pub device: DeviceChoice,
    /// Training exercise (e.g. config/exercises/slab_depth.ron): its scene with the plan
    /// drawn on the tissue; A finishes an attempt (scored, saved under OUT/attempts/,
    /// the result card shown above the tray), A again starts over.
    #[arg(long, conflicts_with = "scene", value_parser = config_file)]
    pub exercise: Option<PathBuf>,
    /// Results history exercise attempts are appended to.
    #[arg(long, default_value = "results/history.jsonl")]
    pub history: PathBuf,
    /// Testing aid: give a node a NaN velocity just before simulation frame N (the
    /// frame is rolled back, an exercise attempt saved, the scene reset).
    #[arg(long, value_name = "N")]
    pub inject_nan_at: Option<u64>,
    /// Drive the scalpel along this recorded stroke (RON, e.g. a session's stroke.ron)
    /// in simulation time instead of the right controller, blade engaged; the session
    /// ends when the stroke has been played (for demos and tests).
    #[arg(long, value_name = "FILE")]
    pub stroke: Option<PathBuf>,
    /// Where the solver is stepped: on its own thread paced to real time, each display
    /// frame showing its latest completed state (the display never waits for it), or
    /// inside each display frame (lockstep, deterministic). auto: the thread, except
    /// in exercise sessions and on a simulated headset's virtual clock.
    #[arg(long, value_enum, default_value_t = SimChoice::Auto)]
    pub sim: SimChoice,
    /// Testing aid: sleep N ms in every simulation frame (an artificially slow solver).
    #[arg(long, value_name = "N", default_value_t = 0, hide = true)]
    pub slow_sim_ms: u64,
    /// Testing aid: panic in the simulation just before simulation frame N.
    #[arg(long, value_name = "N", hide = true)]
    pub inject_sim_panic_at: Option<u64>,
}

impl From<RunArgs> for RunOptions {
    fn from(a: RunArgs) -> Self {
        RunOptions {
            scene: a.scene,
            frames: a.frames,
            out: a.out,
            vtu_every: a.vtu_every,
            threads: a.threads,
            quiet: a.quiet,
            device: a.device,
            screenshot_every: a.screenshot_every,
            screenshot_size: a.screenshot_size,
            haptic_rate: a.haptic_rate,
            stroke: a.stroke,
            record_stroke: a.record_stroke,
            replay_localisation: a.replay_localisation,
            inject_gpu_loss_at: a.inject_gpu_loss_at,
            inject_nan_at: a.inject_nan_at,
            screenshot_decal: None,
        }
    }
}

impl From<PreviewArgs> for PreviewOptions {
    fn from(a: PreviewArgs) -> Self {
        PreviewOptions {
            scene: a.scene,
            frames: a.frames,
            screenshot: a.screenshot,
            device: a.device,
            size: a.size,
            exercise: a.exercise,
        }
    }
}

impl From<XrArgs> for XrOptions {
    fn from(a: XrArgs) -> Self {
        XrOptions {
            scene: a.scene,
            simulated: a.simulated_headset,
            out: a.out,
            record_stroke: a.record_stroke,
            frames: a.frames,
            device: a.device,
            exercise: a.exercise,
            history: a.history,
            inject_nan_at: a.inject_nan_at,
            stroke: a.stroke,
            sim: a.sim,
            slow_sim_ms: a.slow_sim_ms,
            inject_sim_panic_at: a.inject_sim_panic_at,
            scheme: None,
        }
    }
}

/// A file argument as given, else the built-in file of that name
/// ([`crate::scene::built_in::resolve`]): `incise run intestine_pull` works from any
/// folder.
fn config_file(arg: &str) -> Result<PathBuf, String> {
    Ok(resolve(Path::new(arg)))
}

impl Command {
    /// What `incise` with no subcommand does: the preview of [`DEFAULT_SCENE`] when a
    /// window can open, else the headless run of it into out/intestine_pull (as
    /// scripts/run.sh), saying why. Each is the command line it stands for, parsed.
    pub fn default_for_this_machine() -> Command {
        let line: &[&str] = match crate::preview::display::missing_display() {
            None => &["incise", "preview"],
            Some(why) => {
                eprintln!(
                    "{why}: running {DEFAULT_SCENE} headless (`incise --help` lists the commands)"
                );
                &[
                    "incise",
                    "run",
                    DEFAULT_SCENE,
                    "--out",
                    "out/intestine_pull",
                ]
            }
        };
        Cli::parse_from(line)
            .command
            .expect("the default command line names a command")
    }
}

/// `incise scenes` subcommands.
#[derive(Debug, Subcommand)]
pub enum ScenesAction {
    /// Write the built-in config tree (scenes, exercises, presets, tools, strokes, headset
    /// scripts) into DIR, to edit and run from there.
    Export {
        /// Folder to write into (created; files of the same names are replaced).
        dir: PathBuf,
    },
}
