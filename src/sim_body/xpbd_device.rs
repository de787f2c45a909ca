//! The simulated body on the device the user chose: the CPU reference solver or the GPU
//! solver (whose host mirror carries the same accessors).

use anyhow::{Context, Result};
use clap::ValueEnum;
use incise_sim::Solver;
use incise_sim::gpu::{GpuContext, GpuSolver};
use incise_sim::implicit::{Scheme, Smoother};
use incise_sim::xpbd::{FrameStats, SolverError};

/// Where the solver runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum DeviceChoice {
    /// The GPU when an adapter exists, else the CPU with a one-line notice.
    #[default]
    Auto,
    /// The CPU reference solver (on a thread per core).
    Cpu,
    /// The wgpu compute solver; an error when no adapter exists.
    Gpu,
}

/// A compute context on the best adapter, opened as the renderer's headless device is
/// (primary backends first, so a machine without a display prints no window-system
/// errors), with the limits the GPU solver needs.
pub fn gpu_context() -> Result<GpuContext> {
    Ok(incise_xr::RenderDevice::headless()
        .context("opening the GPU solver's device")?
        .compute_context())
}

/// Where `--device auto` runs the solver on a machine whose best adapter is `adapter`,
/// and the sentence saying why. A hardware GPU (discrete, integrated or virtual) gets the
/// GPU solver. A software adapter (Mesa's lavapipe/llvmpipe, WARP: `DeviceType::Cpu`)
/// runs the GPU kernels on the CPU's own cores through an emulation layer, so the CPU
/// solver is faster there (measured on the default scene: lavapipe 1.17–1.29× slower
/// than the CPU solver on the same cores, issue 18); it gets the CPU solver.
pub fn auto_device(adapter: &wgpu::AdapterInfo) -> (DeviceChoice, String) {
    let name = format!(
        "{} ({:?}, {:?})",
        adapter.name, adapter.backend, adapter.device_type
    );
    match adapter.device_type {
        wgpu::DeviceType::Cpu => (
            DeviceChoice::Cpu,
            format!(
                "--device auto: cpu, because the only GPU adapter, {name}, is a software \
                 one running on the CPU, where the CPU solver is faster"
            ),
        ),
        _ => (
            DeviceChoice::Gpu,
            format!("--device auto: gpu, because {name} is a hardware GPU"),
        ),
    }
}

/// Whether the solver's settings exist on the CPU only (the implicit scheme's
/// Gauss–Seidel smoother).
fn cpu_only(solver: &Solver) -> bool {
    matches!(solver.params().scheme, Scheme::Newton(p) if p.smoother == Smoother::GaussSeidel)
}

/// A solver on the CPU or the GPU.
pub enum Body {
    /// CPU reference.
    Cpu(Box<Solver>),
    /// GPU compute, with its adapter description.
    Gpu(Box<GpuSolver>),
}

impl Body {
    /// Put `solver` (pins and grabs applied) on the chosen device. `notice` receives the
    /// line explaining an automatic fall-back to the CPU.
    pub fn place(solver: Solver, choice: DeviceChoice, notice: impl FnOnce(&str)) -> Result<Body> {
        Body::place_on(solver, choice, None, notice)
    }

    /// [`Body::place`] on the open context `gpu` when the choice is the GPU (`None`: a
    /// context is opened for this body).
    pub fn place_on(
        solver: Solver,
        choice: DeviceChoice,
        gpu: Option<&GpuContext>,
        notice: impl FnOnce(&str),
    ) -> Result<Body> {
        let context = || match gpu {
            Some(ctx) => Ok(ctx.clone()),
            None => gpu_context(),
        };
        match choice {
            DeviceChoice::Cpu => Ok(Body::Cpu(Box::new(solver))),
            DeviceChoice::Gpu => {
                let ctx = context()?;
                Ok(Body::Gpu(Box::new(GpuSolver::new(solver, &ctx)?)))
            }
            DeviceChoice::Auto if cpu_only(&solver) => {
                notice(
                    "--device auto: cpu, because the scene's solver.scheme smoother (GaussSeidel) runs on the CPU only",
                );
                Ok(Body::Cpu(Box::new(solver)))
            }
            DeviceChoice::Auto => match context() {
                Ok(ctx) => {
                    let (pick, why) = auto_device(&ctx.info);
                    notice(&why);
                    Ok(match pick {
                        DeviceChoice::Gpu => Body::Gpu(Box::new(GpuSolver::new(solver, &ctx)?)),
                        _ => Body::Cpu(Box::new(solver)),
                    })
                }
                Err(e) => {
                    notice(&format!("--device auto: cpu, because {e:#}"));
                    Ok(Body::Cpu(Box::new(solver)))
                }
            },
        }
    }

    /// The CPU solver from here on: a GPU body gives up its host mirror (the state of the
    /// last completed frame), a CPU body stays as it is.
    pub fn into_cpu(self) -> Body {
        match self {
            Body::Gpu(g) => Body::Cpu(Box::new(g.into_host())),
            cpu => cpu,
        }
    }

    /// Fault injection for tests: lose the GPU device (no effect on the CPU).
    pub fn inject_device_loss(&self) {
        if let Body::Gpu(g) = self {
            g.inject_device_loss();
        }
    }

    /// Fault injection for tests: a NaN velocity on free node `node`.
    pub fn inject_non_finite(&mut self, node: usize) {
        match self {
            Body::Cpu(s) => s.inject_non_finite(node),
            Body::Gpu(g) => g.inject_non_finite(node),
        }
    }

    /// Testing aid: a NaN velocity on the first free node (none: nothing happens); the
    /// next frame must fail and be rolled back.
    pub fn inject_nan(&mut self) {
        let node = self
            .solver()
            .node_kinds()
            .iter()
            .position(|k| *k == incise_sim::xpbd::NodeKind::Free);
        if let Some(node) = node {
            self.inject_non_finite(node);
        }
    }

    /// Advance one frame.
    pub fn step_frame(&mut self) -> Result<FrameStats, SolverError> {
        match self {
            Body::Cpu(s) => s.step_frame(),
            Body::Gpu(g) => g.step_frame(),
        }
    }

    /// Do the next frame's work that does not depend on the tool's pose now
    /// (`Solver::prepare_frame`, `GpuSolver::prepare_frame`).
    pub fn prepare_frame(&mut self) {
        match self {
            Body::Cpu(s) => s.prepare_frame(),
            Body::Gpu(g) => g.prepare_frame(),
        }
    }

    /// Attach `tool` at `pose`, replacing any tool (see `Solver::set_tool`).
    pub fn set_tool(
        &mut self,
        tool: incise_sim::contact::ContactTool,
        pose: incise_sim::contact::ToolPose,
    ) -> Result<(), SolverError> {
        match self {
            Body::Cpu(s) => s.set_tool(tool, pose),
            Body::Gpu(g) => g.set_tool(tool, pose),
        }
    }

    /// Where the tool will be at the end of the next frame.
    pub fn move_tool(&mut self, to: incise_sim::contact::ToolPose) {
        match self {
            Body::Cpu(s) => s.move_tool(to),
            Body::Gpu(g) => g.move_tool(to),
        }
    }

    /// The CPU solver, or the GPU solver's host mirror (positions, stress, cut state).
    pub fn solver(&self) -> &Solver {
        match self {
            Body::Cpu(s) => s,
            Body::Gpu(g) => g.host(),
        }
    }

    /// "cpu" or the adapter's name, backend and type.
    pub fn device(&self) -> String {
        match self {
            Body::Cpu(_) => "cpu".into(),
            Body::Gpu(g) => format!("gpu: {}", g.adapter()),
        }
    }

    /// GPU kernel time of the last frame, ms, where the adapter has timestamps.
    pub fn gpu_frame_ms(&self) -> Option<f64> {
        match self {
            Body::Cpu(_) => None,
            Body::Gpu(g) => g.last_timing().map(|t| t.frame_ms),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An adapter of `device_type` named `name` (no real device needed).
    fn adapter(name: &str, device_type: wgpu::DeviceType) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: name.into(),
            ..wgpu::AdapterInfo::new(device_type, wgpu::Backend::Vulkan)
        }
    }

    /// Every kind of adapter, also those CI never has (a hardware GPU): a software one
    /// gets the CPU solver, any hardware one the GPU, and the reason names the adapter.
    #[test]
    fn auto_device_picks_the_cpu_only_for_a_software_adapter() {
        use wgpu::DeviceType::*;
        for (kind, pick, word) in [
            (Cpu, DeviceChoice::Cpu, "software"),
            (DiscreteGpu, DeviceChoice::Gpu, "hardware"),
            (IntegratedGpu, DeviceChoice::Gpu, "hardware"),
            (VirtualGpu, DeviceChoice::Gpu, "hardware"),
        ] {
            let (got, why) = auto_device(&adapter("Test Adapter 9", kind));
            assert_eq!(got, pick, "{kind:?}: {why}");
            assert!(
                why.contains(word) && why.contains("Test Adapter 9"),
                "{kind:?}: {why}"
            );
        }
    }
}
