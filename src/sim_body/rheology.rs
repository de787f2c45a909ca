//! The three-element rheological body behind [`SimBody`] (PHYSICS.md §3): every tet edge
//! a Voigt unit in series with a damper, integrated with RK4 under the explicit stability
//! limit, pressed flat by the scene's indenter schedule or by a hand-held probe (the tool
//! presses where it is while engaged). Each frame records the indenter depth and the dent
//! of the probe node (the top node under the indenter's centre), so a report shows the
//! press and the creep back. A diverged frame is rolled back to the last completed one.

use std::path::Path;
use std::time::Instant;

use anyhow::{Result, anyhow, bail};
use glam::{DVec2, DVec3, Quat, Vec3};
use incise_sim::TetMesh;
use incise_sim::contact::ToolPose;
use incise_sim::io::{VtuFrame, write_vtu};
use incise_sim::rheology::{FlatIndenter, PressSchedule, RheologyBody as Model, RheologyState};

use super::body_view::{Quantity, TetView};
use super::interface::{Fault, SimBody, StepError, Surface, ToolInput};
use super::outcome::{Outcome, StateHash};
use crate::report::{EdgeFrameStats, FrameData, Report};
use crate::scene::IndenterSpec;
use crate::scene::Method;

/// The heat map of a rheological body: the mean edge strain magnitude at each node.
const STRAIN: Quantity = Quantity {
    name: "edge strain",
    unit: "1",
};

/// A hand-held probe's schedule: at its depth from the first instant and for good.
const HELD: PressSchedule = PressSchedule {
    depth: 0.0,
    press: 1e-12,
    hold: 1e12,
    lift: 1.0,
};

/// The flat face that presses the top: where it is, how big, and the scene's schedule.
#[derive(Debug, Clone)]
pub struct Press {
    /// Centre of the face in x, y, m (the scene's indenter, else the top's middle).
    pub centre: DVec2,
    /// Half extents of the face, m (the scene's, else a sixth of the top's width).
    pub half_size: DVec2,
    /// Height of the undeformed top, m.
    pub rest_top: f64,
    /// The scene's press-hold-lift schedule, if it has an indenter.
    pub schedule: Option<PressSchedule>,
    /// The top node nearest the centre, whose dent the report records.
    pub probe: usize,
}

impl Press {
    /// The press of a mesh with the scene's `indenter` (if any).
    pub fn of_scene(mesh: &TetMesh, indenter: Option<&IndenterSpec>) -> Press {
        let (lo, hi) = incise_sim::mesh::bounds(&mesh.rest_positions);
        let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
        let middle = DVec2::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
        let centre = indenter.map_or(middle, |i| i.centre);
        let half_size = indenter.map_or((hi - lo).truncate() / 6.0, |i| i.half_size);
        let schedule = indenter.map(|ind| PressSchedule {
            depth: ind.depth,
            press: ind.press,
            hold: ind.hold,
            lift: ind.lift,
        });
        Press {
            centre,
            half_size,
            rest_top: hi.z,
            schedule,
            probe: probe_node(mesh, hi.z, centre),
        }
    }

    /// The indenter face for `tool`: the scene's schedule, or the hand's probe at the
    /// tool's height (engaged) or none (released).
    fn face(&self, tool: &ToolInput, nodes: usize) -> Option<FlatIndenter> {
        let (centre, schedule) = match tool {
            ToolInput::Script => (self.centre, self.schedule?),
            ToolInput::Hand { engaged: false, .. } => return None,
            ToolInput::Hand { pose, .. } => {
                let p = pose.position.as_dvec3();
                let depth = (self.rest_top - p.z).max(0.0);
                (p.truncate(), PressSchedule { depth, ..HELD })
            }
        };
        Some(FlatIndenter {
            centre: centre.to_array(),
            half_size: self.half_size.to_array(),
            rest_top: self.rest_top,
            schedule,
            // Every node can touch the face: it only pushes those under it and above it.
            candidates: (0..nodes as u32).collect(),
        })
    }
}

/// A rheological body with its mesh, press and dent figures.
pub struct RheologyBody {
    model: Model,
    /// Positions, velocities, ratios and time after the last completed frame (what a
    /// failed frame rolls back to; the rest of the model does not change).
    last_good: RheologyState,
    mesh: TetMesh,
    press: Press,
    /// Whether the last frame's face came from a hand (which replaces it every frame).
    hand: bool,
    /// Face depth below the rest top in the last frame, m (`None`: no face).
    depth: Option<f64>,
    frame_dt: f64,
    frame: u64,
    rest_volume: f64,
    max_dent: f64,
    dent: f64,
}

impl RheologyBody {
    /// The body of `model` on `mesh`, pressed as `press` says, stepped every `frame_dt`.
    pub fn new(model: Model, mesh: TetMesh, press: Press, frame_dt: f64) -> RheologyBody {
        let rest_volume = mesh.rest_volume.iter().map(|&v| v as f64).sum();
        let mut last_good = RheologyState::default();
        model.save_state(&mut last_good);
        let mut body = RheologyBody {
            last_good,
            model,
            mesh,
            press,
            hand: false,
            depth: None,
            frame_dt,
            frame: 0,
            rest_volume,
            max_dent: 0.0,
            dent: 0.0,
        };
        body.set_face(&ToolInput::Script);
        body
    }

    /// The dent of the probe node below its rest height, m.
    pub fn dent(&self) -> f64 {
        self.mesh.rest_positions[self.press.probe].z as f64
            - self.model.position(self.press.probe).z
    }

    /// Put the indenter face where `tool` says (a script's face is set once).
    fn set_face(&mut self, tool: &ToolInput) {
        let hand = matches!(tool, ToolInput::Hand { .. });
        if hand || self.hand || self.frame == 0 {
            let face = self.press.face(tool, self.mesh.node_count());
            self.depth = face.as_ref().map(|f| f.schedule.depth);
            self.model.set_indenter(face);
        }
        self.hand = hand;
    }

    /// The frame's statistics.
    fn stats(&self, steps: usize, solve_ms: f64) -> EdgeFrameStats {
        let positions = self.model.positions();
        let t = self.model.time();
        let depth = match self.hand {
            true => self.depth,
            false => self.press.schedule.map(|s| s.depth_at(t).0),
        };
        EdgeFrameStats {
            frame: self.frame,
            sim_time: t,
            substeps: steps as u64,
            volume_ratio: volume(&self.mesh.tets, &positions) / self.rest_volume,
            max_displacement: max_displacement(&self.mesh.rest_positions, &positions),
            kinetic_energy: Some(self.model.kinetic_energy()),
            solve_ms: Some(solve_ms),
            indenter_depth: depth,
            dent_depth: Some(self.dent),
            ..EdgeFrameStats::default()
        }
    }

    /// The mean edge strain magnitude `|L/L0 − 1|` at each node.
    fn strain_at_nodes(&self) -> Vec<f32> {
        let edges = self.model.edges();
        let (mut sum, mut count) = (
            vec![0.0f64; self.mesh.node_count()],
            vec![0u32; self.mesh.node_count()],
        );
        for (e, &[a, b]) in edges.edges.iter().enumerate() {
            let l = (self.model.position(a as usize) - self.model.position(b as usize)).length();
            let strain = (l / edges.rest_length[e] as f64 - 1.0).abs();
            for n in [a as usize, b as usize] {
                sum[n] += strain;
                count[n] += 1;
            }
        }
        sum.iter()
            .zip(&count)
            .map(|(&s, &c)| if c == 0 { 0.0 } else { (s / c as f64) as f32 })
            .collect()
    }
}

impl SimBody for RheologyBody {
    fn method(&self) -> Method {
        Method::Rheology
    }

    fn frame_dt(&self) -> f64 {
        self.frame_dt
    }

    fn time(&self) -> f64 {
        self.model.time()
    }

    // PHYSICS.md §3, eqs. (1)–(5): RK4 over positions, velocities and ratios.
    fn step(&mut self, tool: &ToolInput) -> Result<FrameData, StepError> {
        self.set_face(tool);
        let t0 = Instant::now();
        let steps = match self.model.advance(self.frame_dt) {
            Ok(n) => n,
            Err(e) => {
                let back = match self.model.restore_state(&self.last_good) {
                    Ok(()) => "rolled back to the last completed frame".to_string(),
                    Err(r) => format!("the rollback failed: {r}"),
                };
                return Err(StepError::Failed(format!("{e} ({back})")));
            }
        };
        let solve_ms = t0.elapsed().as_secs_f64() * 1e3;
        self.dent = self.dent();
        self.max_dent = self.max_dent.max(self.dent);
        let stats = self.stats(steps, solve_ms);
        self.frame += 1;
        self.model.save_state(&mut self.last_good);
        Ok(FrameData::Edges(stats))
    }

    fn tool_pose(&self) -> Option<ToolPose> {
        let depth = self.depth?;
        Some(ToolPose {
            position: self
                .press
                .centre
                .extend(self.press.rest_top - depth)
                .as_vec3(),
            rotation: Quat::IDENTITY,
        })
    }

    fn tool_force(&self) -> Option<Vec3> {
        None
    }

    fn surface(&self) -> Surface {
        Surface {
            positions: self.model.positions().iter().map(|p| p.as_vec3()).collect(),
            triangles: self.mesh.boundary_triangles(),
            cut_triangles: Vec::new(),
            scalar: self.strain_at_nodes(),
            quantity: Some(STRAIN),
        }
    }

    fn tet_view(&self) -> TetView {
        let strain = self.strain_at_nodes();
        TetView {
            positions: self.model.positions().iter().map(|p| p.as_vec3()).collect(),
            tets: self.mesh.tets.clone(),
            per_tet: self
                .mesh
                .tets
                .iter()
                .map(|t| t.iter().map(|&n| strain[n as usize]).sum::<f32>() / 4.0)
                .collect(),
            quantity: Some(STRAIN),
        }
    }

    fn write_vtu(&self, path: &Path) -> Result<()> {
        let positions: Vec<Vec3> = self.model.positions().iter().map(|p| p.as_vec3()).collect();
        let velocity: Vec<Vec3> = (0..self.model.node_count())
            .map(|i| self.model.velocity(i).as_vec3())
            .collect();
        let material: Vec<f32> = self
            .model
            .material_map()
            .tet_material
            .iter()
            .map(|&m| m as f32)
            .collect();
        let strain = self.strain_at_nodes();
        let frame = VtuFrame {
            positions: &positions,
            tets: &self.mesh.tets,
            cell_scalars: vec![("material", &material)],
            point_vectors: vec![("velocity", &velocity)],
            point_scalars: vec![("strain", &strain)],
        };
        write_vtu(path, &frame).map_err(|e| anyhow!("{}: {e}", path.display()))
    }

    fn progress_line(&self, _frame: &FrameData) -> String {
        format!("dent {:.2} mm", self.dent * 1e3)
    }

    fn device(&self) -> String {
        "cpu (rheology)".into()
    }

    fn into_cpu(self: Box<Self>) -> Box<dyn SimBody> {
        self
    }

    fn outcome(&self) -> Option<Outcome> {
        let n = self.model.node_count();
        let mut h = StateHash::new();
        h.reals([self.model.time()])
            .vectors(&self.model.positions())
            .vectors(&(0..n).map(|i| self.model.velocity(i)).collect::<Vec<_>>())
            .reals(self.model.ratios().iter().copied());
        Some(Outcome {
            summary: format!("dent {:.4} mm", self.dent() * 1e3),
            hash: h.finish(),
            released: None,
        })
    }

    fn inject(&mut self, fault: Fault) -> Result<()> {
        match fault {
            Fault::Nan => {
                let node = self.press.probe;
                self.model.set_velocity(node, DVec3::NAN);
                Ok(())
            }
            Fault::DeviceLoss => {
                bail!("the rheology method runs on the CPU: there is no GPU to lose")
            }
        }
    }

    fn finish(&mut self, report: &mut Report) -> Result<Option<String>> {
        if let Some(info) = &mut report.rheology {
            info.max_dent_m = self.max_dent;
            info.residual_dent_m = self.dent;
        }
        Ok(None)
    }
}

/// The node on the top plane (rest z within 1 µm of `top`) nearest `centre` in x, y.
fn probe_node(mesh: &TetMesh, top: f64, centre: DVec2) -> usize {
    let d = |i: usize| (mesh.rest_positions[i].as_dvec3().truncate() - centre).length();
    (0..mesh.node_count())
        .filter(|&i| mesh.rest_positions[i].z as f64 >= top - 1e-6)
        .min_by(|&a, &b| d(a).total_cmp(&d(b)))
        .unwrap_or(0)
}

/// Total volume of `tets` at `x`, m³.
fn volume(tets: &[[u32; 4]], x: &[DVec3]) -> f64 {
    tets.iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|i| x[i as usize]);
            (b - a).cross(c - a).dot(d - a) / 6.0
        })
        .sum()
}

/// Largest distance of a node from its rest position, m.
fn max_displacement(rest: &[Vec3], x: &[DVec3]) -> f64 {
    rest.iter()
        .zip(x)
        .map(|(r, p)| (*p - r.as_dvec3()).length())
        .fold(0.0, f64::max)
}
