//! A running body given a new material or new solver settings (a panel slider, the
//! headset's substep pacing): a new solver that continues from this one's state, so the
//! motion, the cut, the pins, the grabs' progress and the tool carry over unchanged.

use super::solver::{NodeKind, Solver};
use super::{SolverError, SolverParams};
use crate::Material;

impl Solver {
    /// This body with `material` and `params` from now on: positions, velocities,
    /// released tets, pinned, grabbed and retired nodes, the grabs (their paths and
    /// clocks), the tool, and the frame and time counters carry over, so the next frame
    /// continues the motion. Refused (unusable material, unstable substeps) as
    /// [`Solver::new`] refuses; `self` is unchanged either way.
    pub fn retuned(&self, material: Material, params: SolverParams) -> Result<Solver, SolverError> {
        let mut s = Solver::with_tet_order(self.mesh.clone(), material, params, self.tet_order)?;
        s.u.clone_from(&self.u);
        s.u_prev.clone_from(&self.u_prev);
        s.x.clone_from(&self.x);
        s.v.clone_from(&self.v);
        s.start.clone_from(&self.start);
        s.grabs.clone_from(&self.grabs);
        s.tool.clone_from(&self.tool);
        s.near_window.clone_from(&self.near_window);
        s.inverted_frames.clone_from(&self.inverted_frames);
        s.von_mises.clone_from(&self.von_mises);
        s.det_f.clone_from(&self.det_f);
        (s.frame, s.time) = (self.frame, self.time);
        let released: Vec<u32> = (0..self.mesh.tet_count() as u32)
            .filter(|&t| !self.cut.is_live(t as usize))
            .collect();
        s.release(&released);
        // Pins, grabs and retired nodes keep their kind and move only as it says.
        s.kind.clone_from(&self.kind);
        for (k, w) in s.kind.iter().zip(s.inv_mass.iter_mut()) {
            if *k != NodeKind::Free {
                *w = 0.0;
            }
        }
        s.prepare()?;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use crate::contact::{ContactTool, ToolPose, ToolSphere};
    use crate::generate;
    use crate::grab::Grab;
    use crate::mesh::TetMesh;
    use crate::{Material, Solver, SolverParams};

    /// A soft tissue.
    fn soft() -> Material {
        Material {
            youngs_modulus: 3000.0,
            poisson_ratio: 0.45,
            density: 1000.0,
        }
    }

    /// The plate pinned on one side and pulled by a grab on the other, stepped `frames`.
    fn pulled_plate(substeps: u32, frames: usize) -> Solver {
        let (mesh, _) = TetMesh::from_raw(generate::plate()).unwrap();
        let params = SolverParams {
            substeps,
            ..SolverParams::default()
        };
        let mut s = Solver::new(mesh, soft(), params).unwrap();
        let rest = s.mesh().rest_positions.clone();
        let lo = rest.iter().fold(f32::MAX, |m, p| m.min(p.x));
        let hi = rest.iter().fold(f32::MIN, |m, p| m.max(p.x));
        let side = |x: f32| -> Vec<u32> {
            (0..rest.len() as u32)
                .filter(|&i| (rest[i as usize].x - x).abs() < 1e-4)
                .collect()
        };
        s.pin(&side(lo));
        s.add_grab(Grab {
            nodes: side(hi),
            waypoints: vec![Vec3::new(0.01, 0.0, 0.0)],
            speed: 0.02,
            start_time: 0.05,
        });
        let tool = ContactTool {
            spheres: vec![ToolSphere {
                centre: Vec3::ZERO,
                radius: 0.002,
                cutting: false,
            }],
            boxes: Vec::new(),
            friction: 0.0,
        };
        let pose = ToolPose {
            position: Vec3::new(0.0, 0.0, 1.0),
            rotation: glam::Quat::IDENTITY,
        };
        s.set_tool(tool, pose).unwrap();
        for _ in 0..frames {
            s.step_frame().unwrap();
        }
        s
    }

    #[test]
    fn a_retuned_solver_continues_the_motion_the_cut_and_the_grab() {
        let mut a = pulled_plate(20, 4);
        a.release(&[3, 50, 400]);
        let mut b = a.retuned(soft(), a.params().clone()).unwrap();
        assert_eq!((b.frame(), b.time()), (a.frame(), a.time()));
        assert_eq!(b.positions(), a.positions());
        assert_eq!(b.velocities(), a.velocities());
        assert_eq!(b.cut().released_count(), 3);
        assert_eq!(b.tool().unwrap().to, a.tool().unwrap().to);
        // Same settings: the next frames are the same frames, the grab moving on.
        for _ in 0..6 {
            a.step_frame().unwrap();
            b.step_frame().unwrap();
        }
        assert_eq!(b.positions(), a.positions());
    }

    #[test]
    fn fewer_substeps_keep_pulling_where_the_grab_is() {
        let a = pulled_plate(30, 6);
        let mut fewer = a
            .retuned(
                soft(),
                SolverParams {
                    substeps: 20,
                    ..a.params().clone()
                },
            )
            .unwrap();
        let mut more = a.retuned(soft(), a.params().clone()).unwrap();
        for _ in 0..8 {
            fewer.step_frame().unwrap();
            more.step_frame().unwrap();
        }
        // The grabbed side has moved on along its path in both, by the same amount.
        let grabbed = (0..a.mesh().node_count())
            .find(|&i| matches!(a.node_kinds()[i], crate::xpbd::NodeKind::Grabbed(_)))
            .unwrap();
        let moved = |s: &Solver| s.positions()[grabbed] - a.positions()[grabbed];
        assert!(moved(&more).x > 1e-4, "the grab moves: {}", moved(&more));
        assert!((moved(&fewer) - moved(&more)).length() < 1e-6);
    }
}
