//! The Nakao cutter at a haptic rate behind [`SimBody`] (PHYSICS.md §2.6): the localised
//! loop runs on its own thread at the asked rate ([`HapticLoop`]), its tool tip at the
//! middle of the blade edge coupled to the nearest node by a virtual spring, and cuts
//! along the stroke in that thread. A frame here is the report loop's: it waits until
//! the frame's wall-clock deadline, hands the thread the blade pose for its simulated
//! time and records the tool force, loop count and snapshot figures it published.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use glam::{DVec3, Vec3};
use incise_sim::contact::ToolPose;
use incise_sim::mass_spring::{HapticConfig, HapticLoop, LocalLoopParams, MassSpringModel};
use incise_sim::nakao_cut::BladePose;

use super::body_view::TetView;
use super::interface::{Fault, SimBody, StepError, Surface, ToolInput};
use super::nakao_blade::{Blade, tool_point};
use super::outcome::Outcome;
use crate::report::{EdgeFrameStats, FrameData, HapticInfo, Report};
use crate::scene::Method;
use crate::scene::{Localisation, MassSpringScene, StrokeSpec};

/// The model, on this thread before the first frame and after the last, else on the
/// haptic thread.
enum Holder {
    Here(Box<MassSpringModel>),
    Thread { haptic: HapticLoop, start: Instant },
    Stopped,
}

/// A Nakao body whose loop runs on its own thread at a haptic rate.
pub struct NakaoHapticBody {
    holder: Holder,
    config: HapticConfig,
    blade: Blade,
    pose: Option<BladePose>,
    blade_down: bool,
    frame_dt: f64,
    frame: u64,
    previous_loops: u64,
    max_force: f64,
    last_force: DVec3,
    last_time: f64,
}

impl NakaoHapticBody {
    /// `model` with the scene's cut and localisation, to run at `rate` Hz along `stroke`
    /// beside a report loop of `frame_dt`; the thread starts with the first frame.
    pub fn spawn(
        model: MassSpringModel,
        ms: &MassSpringScene,
        stroke: StrokeSpec,
        rate: f64,
        frame_dt: f64,
    ) -> NakaoHapticBody {
        NakaoHapticBody {
            holder: Holder::Here(Box::new(model)),
            config: HapticConfig {
                rate_hz: rate,
                publish_hz: 1.0 / frame_dt,
                local: haptic_localisation(ms.localisation),
                cut: ms.cut.clone(),
                contact: ms.haptic_contact,
                ..HapticConfig::default()
            },
            blade: Blade::of_stroke(Some(stroke)),
            pose: None,
            blade_down: false,
            frame_dt,
            frame: 0,
            previous_loops: 0,
            max_force: 0.0,
            last_force: DVec3::ZERO,
            last_time: 0.0,
        }
    }

    /// Start the haptic thread with the model (the first frame does).
    fn start_thread(&mut self) {
        if let Holder::Here(_) = self.holder {
            let Holder::Here(model) = std::mem::replace(&mut self.holder, Holder::Stopped) else {
                return;
            };
            let start = Instant::now();
            let haptic = HapticLoop::spawn(*model, self.config.clone());
            let first = self.blade.at(&ToolInput::Script, 0.0, None);
            haptic.set_tool(first.map(|(p, _, _)| tool_point(p)));
            self.holder = Holder::Thread { haptic, start };
        }
    }
}

impl SimBody for NakaoHapticBody {
    fn method(&self) -> Method {
        Method::Nakao
    }

    fn frame_dt(&self) -> f64 {
        self.frame_dt
    }

    fn time(&self) -> f64 {
        self.last_time
    }

    fn step(&mut self, tool: &ToolInput) -> Result<FrameData, StepError> {
        self.start_thread();
        let Holder::Thread { haptic, start } = &self.holder else {
            return Err(StepError::Failed("the haptic loop has been stopped".into()));
        };
        let deadline = *start + Duration::from_secs_f64((self.frame + 1) as f64 * self.frame_dt);
        if let Some(wait) = deadline.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        let latest = haptic.latest();
        // The stroke's first pose places the blade, later ones cut, its end lifts it.
        if let Some((pose, engaged, begin)) = self.blade.at(tool, latest.sim_time, self.pose) {
            haptic.set_tool(Some(tool_point(pose)));
            haptic.set_blade(match (engaged, self.blade_down) {
                (true, false) => Some(begin),
                (true, true) | (false, true) => Some(pose),
                (false, false) => None,
            });
            self.blade_down = engaged;
            self.pose = Some(pose);
        }
        let force = latest.tool_force;
        self.max_force = self.max_force.max(force.length());
        self.last_force = force;
        self.last_time = latest.sim_time;
        let stats = EdgeFrameStats {
            frame: self.frame,
            sim_time: latest.sim_time,
            substeps: latest.loops - self.previous_loops,
            volume_ratio: latest.volume_ratio,
            max_displacement: latest.max_displacement,
            kinetic_energy: Some(latest.kinetic_energy),
            solve_ms: None,
            tool_force: Some(force.to_array()),
            haptic_loops: Some(latest.loops),
            ..EdgeFrameStats::default()
        };
        self.previous_loops = latest.loops;
        self.frame += 1;
        Ok(FrameData::Edges(stats))
    }

    fn tool_pose(&self) -> Option<ToolPose> {
        super::nakao_blade::tool_pose(self.pose)
    }

    fn tool_force(&self) -> Option<Vec3> {
        Some(self.last_force.as_vec3())
    }

    fn surface(&self) -> Surface {
        match &self.holder {
            Holder::Here(m) => super::nakao::surface_of(m),
            Holder::Thread { haptic, .. } => Surface {
                positions: haptic
                    .latest()
                    .positions
                    .iter()
                    .map(|p| p.as_vec3())
                    .collect(),
                ..Surface::default()
            },
            Holder::Stopped => Surface::default(),
        }
    }

    fn tet_view(&self) -> TetView {
        match &self.holder {
            Holder::Here(m) => super::nakao::tet_view_of(m),
            _ => TetView::default(),
        }
    }

    fn holds_state(&self) -> bool {
        matches!(self.holder, Holder::Here(_))
    }

    fn write_vtu(&self, path: &Path) -> Result<()> {
        match &self.holder {
            Holder::Here(m) => super::nakao::write_model_vtu(m, path),
            _ => bail!(
                "{}: the haptic thread holds the model; a haptic-rate run writes its first \
                 snapshot only",
                path.display()
            ),
        }
    }

    fn progress_line(&self, _frame: &FrameData) -> String {
        format!("tool force {:.3} N", self.last_force.length())
    }

    fn device(&self) -> String {
        "cpu (mass-spring)".into()
    }

    fn into_cpu(self: Box<Self>) -> Box<dyn SimBody> {
        self
    }

    fn outcome(&self) -> Option<Outcome> {
        match &self.holder {
            Holder::Here(m) => Some(super::nakao_outcome::model_outcome(m)),
            _ => None,
        }
    }

    fn inject(&mut self, fault: Fault) -> Result<()> {
        bail!("{fault:?} cannot be injected into the haptic thread's model")
    }

    fn finish(&mut self, report: &mut Report) -> Result<Option<String>> {
        let Holder::Thread { haptic, start } = std::mem::replace(&mut self.holder, Holder::Stopped)
        else {
            return Ok(None);
        };
        let last = haptic.latest();
        let wall_s = start.elapsed().as_secs_f64();
        let model = haptic
            .stop()
            .map_err(|_| anyhow!("the haptic thread panicked"))?;
        let info = HapticInfo {
            requested_hz: self.config.rate_hz,
            loops: last.loops,
            wall_s,
            achieved_hz: last.loops as f64 / wall_s,
            overruns: last.overruns,
            sim_time: last.sim_time,
            snapshots: last.snapshots,
            report_hz: 1.0 / self.frame_dt,
            cut_advances: last.cut_advances,
            last_tool_force: last.tool_force.to_array(),
            max_tool_force: self.max_force.max(last.tool_force.length()),
        };
        if !(info.achieved_hz.is_finite() && info.last_tool_force.iter().all(|f| f.is_finite())) {
            bail!("the haptic loop produced a non-finite rate or tool force: {info:?}");
        }
        report.haptic = Some(info);
        let line = super::nakao::counts_into(&model, report, self.frame);
        self.holder = Holder::Here(Box::new(model));
        Ok(Some(line))
    }
}

/// The haptic loop's localisation: the scene's level or budget; `Whole` keeps the loop's
/// default level 4 (a 1 kHz loop cannot integrate a large mesh whole).
fn haptic_localisation(l: Localisation) -> LocalLoopParams {
    match l {
        Localisation::Whole => LocalLoopParams::default(),
        Localisation::Level(d) => LocalLoopParams {
            max_level: d,
            ..LocalLoopParams::default()
        },
        Localisation::Budget(ms) => LocalLoopParams {
            budget_ms: Some(ms),
            max_level: u32::MAX,
            ..LocalLoopParams::default()
        },
    }
}
