//! The Nakao tension mass-spring cutter behind [`SimBody`], frame by frame (PHYSICS.md
//! §2.1–2.5): each frame advances the blade (cutting: remodelling and adaptive
//! subdivision), then takes the frame's explicit steps on the whole mesh or on the nodes
//! the localisation frees around the blade: a fixed level d, or the refresh-rate manager,
//! which picks the level each frame from the time the last one took. Every frame records
//! the level, the free nodes and the loop-time split. A frame that leaves a non-finite
//! position is rolled back to the last completed one.

use std::path::Path;
use std::time::Instant;

use anyhow::{Result, bail};
use glam::{DVec3, Vec3};
use incise_scalpel::Stroke;
use incise_sim::contact::ToolPose;
use incise_sim::io::{VtuFrame, write_vtu};
use incise_sim::mass_spring::{
    DynamicState, HapticConfig, LocalLoop, LocalLoopParams, MassSpringModel, SystemClock,
    ToolCoupling,
};
use incise_sim::nakao_cut::measure::{counts, cut_surface_area, cut_triangles, opening_width};
use incise_sim::nakao_cut::{BladePose, Cutter};

use super::body_view::{Quantity, TetView};
use super::interface::{Fault, SimBody, StepError, Surface, ToolInput};
use super::nakao_blade::{Blade, stroke_hand, tool_point, touches};
use super::nakao_outcome::model_outcome;
use super::nakao_surface::{max_displacement, surface_triangles, tension_at_nodes};
use super::outcome::Outcome;
use super::rest_cut::{RestCut, cut_faces_at_rest};
use crate::report::localisation::{LocalisationInfo, LoopSample, LoopSplit};
use crate::report::{EdgeFrameStats, FrameData, NakaoInfo, Report};
use crate::scene::Method;
use crate::scene::{Localisation, MassSpringScene};

/// The heat map of a Nakao body: the spring tension at each node.
const TENSION: Quantity = Quantity {
    name: "spring tension",
    unit: "N",
};

/// A Nakao body stepped frame by frame, with its blade and localisation.
pub struct NakaoBody {
    model: MassSpringModel,
    /// The model after the last frame whose cut remodelled it: the topology of the last
    /// completed frame (a failed frame that remodelled rolls back to it).
    last_good: MassSpringModel,
    /// Positions, velocities and time after the last completed frame (what every failed
    /// frame rolls back to): saved every frame, while the whole model is copied only
    /// when a cut changed it.
    last_state: DynamicState,
    cutter: Cutter,
    cutting: bool,
    blade: Blade,
    /// Where the blade edge was at the end of the last frame.
    pose: Option<BladePose>,
    /// Where the scalpel showing the blade is drawn (the hand's pose, or the script's
    /// blade turned to lead along its travel).
    drawn: Option<ToolPose>,
    local: Option<LocalLoop>,
    localisation: Localisation,
    samples: Vec<LoopSample>,
    forces: Vec<DVec3>,
    frame_dt: f64,
    frame: u64,
    total_volume: f64,
    /// Force of the tissue on a hand's tool in the last frame (`None`: scripted blade).
    force: Option<DVec3>,
    /// How a hand's tool is coupled to the tissue (the scene's `haptic_contact`).
    coupling: ToolCoupling,
    /// A stroke file that drives the blade as a hand would, in place of the scene's script.
    hand_stroke: Option<Stroke>,
    /// How near a node the blade's edge must pass to touch the tissue: half the mean
    /// reference edge length, m.
    reach: f64,
    /// Whether the engaged blade touched the tissue in the last frame.
    touched: bool,
}

impl NakaoBody {
    /// The body of `model` with the scene's stroke, cut settings and localisation, stepped
    /// every `frame_dt` seconds.
    pub fn new(model: MassSpringModel, ms: &MassSpringScene, frame_dt: f64) -> NakaoBody {
        let total_volume = (0..model.tet_count())
            .map(|t| model.reference_volume(t))
            .sum();
        let mut last_state = DynamicState::default();
        model.save_state(&mut last_state);
        let reach = 0.5 * mean_edge_length(&model);
        NakaoBody {
            last_good: model.clone(),
            last_state,
            model,
            cutter: Cutter::new(ms.cut.clone()),
            cutting: false,
            blade: Blade::of_stroke(ms.stroke.clone()),
            pose: None,
            drawn: None,
            local: local_loop(ms.localisation),
            localisation: ms.localisation,
            samples: Vec::new(),
            forces: Vec::new(),
            frame_dt,
            frame: 0,
            total_volume,
            force: None,
            coupling: HapticConfig {
                contact: ms.haptic_contact,
                ..HapticConfig::default()
            }
            .tool_coupling(),
            hand_stroke: None,
            reach,
            touched: false,
        }
    }

    /// The body with its blade driven by `stroke` (a recorded or reference stroke file)
    /// wherever the scene's script would drive it.
    pub fn with_stroke(mut self, stroke: Stroke) -> NakaoBody {
        self.hand_stroke = Some(stroke);
        self
    }

    /// The body with its localised frames' free nodes replayed from a recorded run
    /// ([`LocalLoop::replay`]) instead of chosen anew; a whole-mesh scene ignores them.
    pub fn with_free_nodes(mut self, free_nodes: Vec<usize>) -> NakaoBody {
        if let Some(l) = &mut self.local {
            l.replay(free_nodes);
        }
        self
    }

    /// The model as of the last completed frame.
    pub fn model(&self) -> &MassSpringModel {
        &self.model
    }

    /// Move the blade as `tool` says and cut where it is engaged; the cut's ms and
    /// whether it remodelled the model.
    // PHYSICS.md §2.3–2.4: the cutter remodels and subdivides along the blade's sweep.
    fn cut(&mut self, tool: &ToolInput) -> (f64, bool) {
        let Some((pose, engaged, begin)) = self.blade.at(tool, self.model.time(), self.pose) else {
            self.touched = false;
            return (0.0, false);
        };
        self.pose = Some(pose);
        self.drawn = Some(self.blade.drawn(tool, pose));
        self.touched = engaged && touches(&self.model, pose, self.reach);
        if engaged && !self.cutting {
            self.cutter.begin(&self.model, begin);
            self.cutting = true;
        }
        if !self.cutting {
            return (0.0, false);
        }
        let report = self.cutter.advance(&mut self.model, pose);
        if !engaged {
            self.cutter.end();
            self.cutting = false;
        }
        (report.ms, report.remodelled)
    }

    /// The frame's `steps` explicit steps of `dt`, localised around the blade when the
    /// scene asks for it; the localisation figures.
    // PHYSICS.md §2.1 (eq. 2) and §2.5 (localisation, refresh-rate manager).
    fn integrate(&mut self, dt: f64, steps: u32, cut_ms: f64) -> LoopSample {
        let tip = self.pose.map(tool_point);
        if let (Some(l), Some(tip)) = (&mut self.local, tip) {
            let s = l.frame(&mut self.model, tip, dt, steps);
            return LoopSample {
                level: Some(s.level()),
                free_nodes: s.free_nodes,
                split: LoopSplit {
                    localise_ms: s.localise_ms,
                    force_ms: s.force_ms,
                    integrate_ms: s.integrate_ms,
                    cut_ms,
                },
            };
        }
        let (force_ms, integrate_ms) = whole_frame(&mut self.model, dt, steps, &mut self.forces);
        LoopSample {
            level: None,
            free_nodes: self.model.node_count(),
            split: LoopSplit {
                localise_ms: 0.0,
                force_ms,
                integrate_ms,
                cut_ms,
            },
        }
    }

    /// The report's statistics of the frame just stepped.
    fn stats(&self, steps: u32, wall_ms: f64, sample: &LoopSample) -> EdgeFrameStats {
        let m = &self.model;
        let volume: f64 = (0..m.tet_count()).map(|t| m.current_volume(t)).sum();
        EdgeFrameStats {
            frame: self.frame,
            sim_time: m.time(),
            substeps: steps as u64,
            volume_ratio: volume / self.total_volume,
            max_displacement: max_displacement(m.reference_positions(), m.positions()),
            kinetic_energy: Some(m.kinetic_energy()),
            solve_ms: Some(wall_ms),
            level: sample.level,
            free_nodes: Some(sample.free_nodes),
            localise_ms: Some(sample.split.localise_ms),
            force_ms: Some(sample.split.force_ms),
            integrate_ms: Some(sample.split.integrate_ms),
            cut_ms: Some(sample.split.cut_ms),
            tool_force: self.force.map(|f| f.to_array()),
            blade_contact: Some(self.touched),
            ..EdgeFrameStats::default()
        }
    }

    /// A hand's tool point (the middle of the blade edge) coupled to the tissue for the
    /// frame as the scene's `haptic_contact` says, by the haptic loop's virtual spring
    /// (PHYSICS.md §2.6); the force of the tissue on the tool.
    fn couple(&mut self) -> DVec3 {
        let Some(p) = self.pose else {
            return DVec3::ZERO;
        };
        let tip = tool_point(p);
        let nodes = self
            .coupling
            .nodes(&self.model, tip, |m, q| m.nearest_node(q));
        self.coupling.pull(&mut self.model, &nodes, tip)
    }

    /// Go back to the last completed frame, the blade lifted: its topology too when this
    /// frame's cut `remodelled` the model. An error when the saved state does not fit
    /// (a remodelling frame that did not say so).
    fn roll_back(&mut self, remodelled: bool) -> Result<(), String> {
        if remodelled {
            self.model.clone_from(&self.last_good);
        }
        if self.cutting {
            self.cutter.end();
            self.cutting = false;
        }
        self.model
            .restore_state(&self.last_state)
            .map_err(|e| e.to_string())
    }

    /// Keep the frame just completed for a rollback: its state, and the whole model when
    /// its cut `remodelled` it.
    fn keep(&mut self, remodelled: bool) {
        if remodelled {
            self.last_good.clone_from(&self.model);
        }
        self.model.save_state(&mut self.last_state);
    }
}

impl SimBody for NakaoBody {
    fn method(&self) -> Method {
        Method::Nakao
    }

    fn frame_dt(&self) -> f64 {
        self.frame_dt
    }

    fn time(&self) -> f64 {
        self.model.time()
    }

    fn step(&mut self, tool: &ToolInput) -> Result<FrameData, StepError> {
        let t0 = Instant::now();
        let tool = &match (&self.hand_stroke, tool) {
            (Some(s), ToolInput::Script) => stroke_hand(s, self.model.time() + self.frame_dt),
            _ => *tool,
        };
        let (cut_ms, remodelled) = self.cut(tool);
        self.force = matches!(tool, ToolInput::Hand { .. }).then(|| self.couple());
        let steps = (self.frame_dt / self.model.stable_dt()).ceil().max(1.0) as u32;
        let sample = self.integrate(self.frame_dt / steps as f64, steps, cut_ms);
        self.model.clear_external_forces();
        if let Some(i) = self.model.positions().iter().position(|p| !p.is_finite()) {
            let back = match self.roll_back(remodelled) {
                Ok(()) => "rolled back to the last completed frame".to_string(),
                Err(e) => format!("the rollback failed: {e}"),
            };
            return Err(StepError::Failed(format!(
                "frame {}: node {i} has a non-finite position; {back}",
                self.frame
            )));
        }
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        self.samples.push(sample);
        let stats = self.stats(steps, wall_ms, &sample);
        self.frame += 1;
        self.keep(remodelled);
        Ok(FrameData::Edges(stats))
    }

    fn tool_pose(&self) -> Option<ToolPose> {
        super::nakao_blade::tool_pose(self.pose)
    }

    fn scalpel_pose(&self) -> Option<ToolPose> {
        self.drawn
    }

    fn tool_force(&self) -> Option<Vec3> {
        self.force.map(|f| f.as_vec3())
    }

    fn surface(&self) -> Surface {
        surface_of(&self.model)
    }

    fn tet_view(&self) -> TetView {
        tet_view_of(&self.model)
    }

    fn write_vtu(&self, path: &Path) -> Result<()> {
        write_model_vtu(&self.model, path)
    }

    fn progress_line(&self, frame: &FrameData) -> String {
        match frame {
            FrameData::Edges(s) => format!(
                "{} nodes, max displacement {:.2} mm",
                self.model.node_count(),
                s.max_displacement * 1e3
            ),
            FrameData::Xpbd(_) => String::new(),
        }
    }

    fn device(&self) -> String {
        "cpu (mass-spring)".into()
    }

    fn into_cpu(self: Box<Self>) -> Box<dyn SimBody> {
        self
    }

    fn outcome(&self) -> Option<Outcome> {
        Some(model_outcome(&self.model))
    }

    fn rest_cut(&self) -> Option<RestCut> {
        Some(cut_faces_at_rest(&self.model))
    }

    fn inject(&mut self, fault: Fault) -> Result<()> {
        match fault {
            Fault::Nan => {
                let free =
                    (0..self.model.node_count()).find(|&i| !self.model.fixed_axes(i).is_pinned());
                if let Some(i) = free {
                    self.model.set_position(i, DVec3::NAN);
                }
                Ok(())
            }
            Fault::DeviceLoss => bail!("the Nakao method runs on the CPU: there is no GPU to lose"),
        }
    }

    fn finish(&mut self, report: &mut Report) -> Result<Option<String>> {
        if self.cutting {
            self.cutter.end();
            self.cutting = false;
        }
        let budget = match self.localisation {
            Localisation::Budget(b) => Some(b),
            _ => None,
        };
        report.localisation =
            LocalisationInfo::of(self.localisation.label(), budget, &self.samples);
        Ok(Some(counts_into(&self.model, report, self.frame)))
    }
}

/// The surface of `m` with its spring tension per node.
pub fn surface_of(m: &MassSpringModel) -> Surface {
    Surface {
        positions: m.positions().iter().map(|p| p.as_vec3()).collect(),
        triangles: surface_triangles(m),
        cut_triangles: cut_triangles(m),
        scalar: tension_at_nodes(m),
        quantity: Some(TENSION),
    }
}

/// `m` as tets with the mean spring tension of each tet's nodes.
pub fn tet_view_of(m: &MassSpringModel) -> TetView {
    let tension = tension_at_nodes(m);
    TetView {
        positions: m.positions().iter().map(|p| p.as_vec3()).collect(),
        tets: m.tets().to_vec(),
        per_tet: m
            .tets()
            .iter()
            .map(|t| t.iter().map(|&n| tension[n as usize]).sum::<f32>() / 4.0)
            .collect(),
        quantity: Some(TENSION),
    }
}

/// Write `m` as a `.vtu` at `path`: per tet its cut faces, per node velocity and tension.
pub fn write_model_vtu(m: &MassSpringModel, path: &Path) -> Result<()> {
    let positions: Vec<Vec3> = m.positions().iter().map(|p| p.as_vec3()).collect();
    let velocity: Vec<Vec3> = m.velocities().iter().map(|v| v.as_vec3()).collect();
    let cut: Vec<f32> = m
        .tet_cut_faces()
        .iter()
        .map(|f| f.count_ones() as f32)
        .collect();
    let tension = tension_at_nodes(m);
    let frame = VtuFrame {
        positions: &positions,
        tets: m.tets(),
        cell_scalars: vec![("cut_faces", &cut)],
        point_vectors: vec![("velocity", &velocity)],
        point_scalars: vec![("tension", &tension)],
    };
    Ok(write_vtu(path, &frame)?)
}

/// Put `m`'s counts after cutting into the report's mesh figures and its Nakao section
/// (added nodes and tets against the report's opening counts, the wound's opening);
/// the closing line.
pub fn counts_into(m: &MassSpringModel, report: &mut Report, frames: u64) -> String {
    let after = counts(m);
    report.nakao = Some(NakaoInfo {
        nodes_added: after.nodes.saturating_sub(report.mesh.nodes),
        tets_added: after.tets.saturating_sub(report.mesh.tets),
        cut_area_m2: cut_surface_area(m),
        opening_width_m: opening_width(m, DVec3::ZERO, f64::INFINITY),
    });
    report.mesh.nodes = after.nodes;
    report.mesh.tets = after.tets;
    report.mesh.skin_vertices = after.nodes;
    report.mesh.skin_triangles = after.triangles;
    format!(
        "mass-spring: {} nodes, {} tets, {} edges after {frames} frames",
        after.nodes, after.tets, after.edges
    )
}

/// Mean reference length of `m`'s springs (its tet edges), m.
fn mean_edge_length(m: &MassSpringModel) -> f64 {
    let x = m.reference_positions();
    let (sum, n) = (0..m.node_count())
        .flat_map(|i| m.springs_of(i).iter().map(move |s| (i, s.node as usize)))
        .fold((0.0, 0usize), |(sum, n), (i, j)| {
            (sum + (x[i] - x[j]).length(), n + 1)
        });
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// The localised loop of a scene's setting (`None` for `Whole`).
fn local_loop(l: Localisation) -> Option<LocalLoop> {
    let params = match l {
        Localisation::Whole => return None,
        Localisation::Level(d) => LocalLoopParams {
            max_level: d,
            ..LocalLoopParams::default()
        },
        Localisation::Budget(ms) => LocalLoopParams {
            budget_ms: Some(ms),
            max_level: u32::MAX,
            ..LocalLoopParams::default()
        },
    };
    Some(LocalLoop::new(params, SystemClock::default()))
}

/// `steps` steps of `dt` on every node, timed by phase: (force ms, integrate ms).
// PHYSICS.md §2.1, eqs. 1–2.
fn whole_frame(
    model: &mut MassSpringModel,
    dt: f64,
    steps: u32,
    forces: &mut Vec<DVec3>,
) -> (f64, f64) {
    let all: Vec<u32> = (0..model.node_count() as u32).collect();
    let (mut force_ms, mut integrate_ms) = (0.0, 0.0);
    for _ in 0..steps {
        let a = Instant::now();
        model.gather_forces(&all, forces);
        let b = Instant::now();
        model.integrate_nodes(dt, &all, forces);
        force_ms += (b - a).as_secs_f64() * 1e3;
        integrate_ms += b.elapsed().as_secs_f64() * 1e3;
    }
    (force_ms, integrate_ms)
}
