//! How a tool point is coupled to the tissue (PHYSICS.md §2.6): a virtual spring from
//! the tool tip to the node nearest it, or to a god object riding the surface (Zilles &
//! Salisbury 1995, [`GodObject`]). The haptic loop and the frame-rate Nakao body both
//! couple through it.

use glam::DVec3;

use super::god_object::{GodObject, ProxySurface};
use super::{LocalLoop, MassSpringModel, SystemClock};

/// The coupling of the tool point to the tissue, both a virtual spring of stiffness
/// `HapticConfig::coupling`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum HapticContact {
    /// To the node nearest the tip, within `HapticConfig::contact_radius`: pulls as well
    /// as pushes (a blade held in the cut), and the force steps when the nearest node
    /// changes (default; what the cutting runs use).
    #[default]
    NearestNode,
    /// To a god object riding the surface (Zilles & Salisbury 1995, [`GodObject`]): a
    /// probe pushes the surface in and feels it push back, never pulls, and cannot pass
    /// through the body.
    GodObject,
}

/// A tool's coupling: the settings and, for a god object, its proxy and the surface it
/// rides (rebuilt when a cut changes the tets).
#[derive(Debug, Clone, Default)]
pub struct ToolCoupling {
    contact: HapticContact,
    stiffness: f64,
    radius: f64,
    god: GodObject,
    surface: ProxySurface,
}

impl ToolCoupling {
    /// A coupling by `contact` with a spring of `stiffness`, N/m, reaching nodes within
    /// `radius`, m (nearest-node contact).
    pub fn new(contact: HapticContact, stiffness: f64, radius: f64) -> Self {
        ToolCoupling {
            contact,
            stiffness,
            radius,
            ..ToolCoupling::default()
        }
    }

    /// One haptic loop's `substeps` with the tool at `tip`, the spring force set again
    /// before each substep: the force on the tool, N, and the free nodes of the last
    /// localised step.
    pub fn haptic_loop(
        &mut self,
        model: &mut MassSpringModel,
        local: &mut LocalLoop<SystemClock>,
        tip: DVec3,
        substeps: u32,
        dt: f64,
    ) -> (DVec3, usize) {
        let nodes = self.nodes(model, tip, |m, p| local.hierarchy().nearest_node(m, p));
        let mut force = DVec3::ZERO;
        let mut free = 0;
        for _ in 0..substeps {
            force = self.pull(model, &nodes, tip);
            free = local.step(model, tip, dt).free_nodes;
        }
        model.clear_external_forces();
        (force, free)
    }

    /// Set the spring's force on `nodes` (weights summing to 1) for the tool at `tip` as
    /// external forces on the model; the force on the tool, N (zero without nodes).
    pub fn pull(&self, model: &mut MassSpringModel, nodes: &[(u32, f64)], tip: DVec3) -> DVec3 {
        if nodes.is_empty() {
            return DVec3::ZERO;
        }
        let x = model.positions();
        let at: DVec3 = nodes.iter().map(|&(n, w)| x[n as usize] * w).sum();
        let force = self.stiffness * (at - tip);
        for &(n, w) in nodes {
            model.set_external_force(n, -force * w);
        }
        force
    }

    /// The nodes the tool at `tip` pulls on, with their weights (summing to 1); none when
    /// it does not touch the tissue. `nearest` finds the node nearest a point.
    pub fn nodes(
        &mut self,
        model: &MassSpringModel,
        tip: DVec3,
        nearest: impl FnOnce(&MassSpringModel, DVec3) -> Option<u32>,
    ) -> Vec<(u32, f64)> {
        match self.contact {
            HapticContact::NearestNode => nearest(model, tip)
                .filter(|&n| (model.positions()[n as usize] - tip).length() <= self.radius)
                .map(|n| vec![(n, 1.0)])
                .unwrap_or_default(),
            HapticContact::GodObject => {
                if self.surface.tet_count() != model.tet_count() {
                    self.surface = ProxySurface::build(model.tets(), model.positions());
                    self.god.rebind(&self.surface, model.positions());
                }
                self.god
                    .update(tip, &self.surface, model.positions())
                    .map(|c| {
                        let t = self.surface.triangles()[c.triangle];
                        (0..3).map(|k| (t[k], c.weights[k])).collect()
                    })
                    .unwrap_or_default()
            }
        }
    }
}
