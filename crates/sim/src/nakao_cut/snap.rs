//! The adaptive node displacement of PHYSICS.md §2.4 (Figs. 5–6).
//!
//! * **Partial crossings**: a tet that C crosses only partially (the cut's boundary B runs
//!   through it) gets one node moved onto B, so that B passes through a node and every
//!   crossing left is one of the two complete patterns. The node moved is the one nearest
//!   to B, straight to its nearest point of B: for a node just ahead of a straight blade
//!   this is the direction of the crossing edges the paper averages, and the paper gives no
//!   rule for how far a node off the plane must go.
//! * **Near-node crossings** (our addition, same mechanism): where C crosses an edge within
//!   `snap_fraction` of a node, the node is moved onto the plane instead of creating a
//!   sliver tet.
//!
//! Every move is refused unless all tets around the node keep a positive volume and a
//! smallest dihedral angle at least `floor_deg` (the non-adaptive split's worst).

use std::collections::HashSet;

use glam::DVec3;

use super::SweptRegion;
use super::crossing::{Crossings, Tolerances};
use super::node_move::try_move;
use crate::mass_spring::MassSpringModel;

/// A node moved by the adaptive cut, with its displacement.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Moved {
    /// The node.
    pub node: u32,
    /// Displacement applied (reference and current), m.
    pub by: DVec3,
}

/// The frame of one advance's node moves: the region, its tolerances, and the smallest
/// dihedral angle (degrees) any tet around a moved node may end with.
pub(crate) struct Snapper<'a> {
    /// The swept region of the advance.
    pub region: &'a SweptRegion,
    /// Its tolerances.
    pub tol: &'a Tolerances,
    /// The floor on the smallest dihedral angle.
    pub floor_deg: f64,
}

impl Snapper<'_> {
    /// Move the nodes whose edges C crosses within `fraction` of them onto the plane.
    pub(crate) fn near_nodes(
        &self,
        model: &mut MassSpringModel,
        crossings: &Crossings,
        fraction: f64,
        moved: &mut Vec<Moved>,
    ) {
        let region = self.region;
        for e in &crossings.split {
            let v = if e.t < fraction {
                e.a
            } else if e.t > 1.0 - fraction {
                e.b
            } else {
                continue;
            };
            if moved.iter().any(|m| m.node == v) {
                continue;
            }
            let x = model.positions()[v as usize];
            let d = -region.signed_distance(x) * region.normal();
            if !region.contains(region.project(x + d), self.tol.in_region) {
                continue;
            }
            if try_move(model, v, d, |_, after| after.min_deg >= self.floor_deg) {
                moved.push(Moved { node: v, by: d });
            }
        }
    }

    /// Move one node of each partially crossed tet onto the boundary B of C (never a node
    /// already on the cut, `on_cut`); returns whether a node moved (the caller recomputes
    /// the crossings and calls again).
    pub(crate) fn to_boundary(
        &self,
        model: &mut MassSpringModel,
        crossings: &Crossings,
        max_move: f64,
        on_cut: &HashSet<u32>,
        moved: &mut Vec<Moved>,
    ) -> bool {
        let region = self.region;
        let mut any = false;
        for &t in &crossings.straddling {
            let tet = model.tets()[t as usize];
            let mut options: Vec<(f64, u32, DVec3)> = tet
                .iter()
                .filter(|&&v| {
                    crossings.distance[&v].abs() > self.tol.on_plane && !on_cut.contains(&v)
                })
                .filter(|&&v| !moved.iter().any(|m| m.node == v))
                .map(|&v| {
                    let x = model.positions()[v as usize];
                    let (_, b) = region.closest_on_boundary(region.project(x));
                    let d = region.lift(b) - x;
                    (d.length(), v, d)
                })
                .filter(|(len, _, _)| *len <= max_move)
                .collect();
            options.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (_, v, d) in options {
                if try_move(model, v, d, |_, after| after.min_deg >= self.floor_deg) {
                    moved.push(Moved { node: v, by: d });
                    any = true;
                    break;
                }
            }
        }
        any
    }
}
