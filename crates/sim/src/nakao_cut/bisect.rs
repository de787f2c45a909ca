//! Edge bisection: split an edge at a point and every tet around it in two (PHYSICS.md
//! §2.4, minimal subdivision). Each tet's mass is split by volume, so mass is conserved.

use super::crossing::SplitEdge;
use crate::mass_spring::{AxisMask, MassSpringModel};

/// What a sequence of bisections changed.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bisection {
    /// Nodes created on the split edges, in split order.
    pub new_nodes: Vec<u32>,
    /// Tets rewritten in place or appended.
    pub touched_tets: Vec<u32>,
}

/// Bisect `split[order[0]]`, then `split[order[1]]`, … at their crossing parameters.
///
/// The new node gets the interpolated reference position, position and velocity; it
/// holds what [`inherited_axes`] gives.
pub(crate) fn bisect_edges(
    model: &mut MassSpringModel,
    split: &[SplitEdge],
    order: &[usize],
) -> Bisection {
    let mut out = Bisection::default();
    for &k in order {
        let SplitEdge { a, b, t } = split[k];
        let (ai, bi) = (a as usize, b as usize);
        let around: Vec<u32> = model
            .tets_of(ai)
            .iter()
            .copied()
            .filter(|&tet| model.tets()[tet as usize].contains(&b))
            .collect();
        if around.is_empty() {
            continue;
        }
        let q = model.add_node(
            model.reference[ai].lerp(model.reference[bi], t),
            model.positions[ai].lerp(model.positions[bi], t),
            model.velocities[ai].lerp(model.velocities[bi], t),
            inherited_axes(model, ai, bi),
        );
        out.new_nodes.push(q);
        for tet in around {
            let parent = model.tets[tet as usize];
            let ia = parent.iter().position(|&v| v == a).unwrap_or(0);
            let ib = parent.iter().position(|&v| v == b).unwrap_or(0);
            let mass = model.tet_mass[tet as usize];
            let flags = model.tet_cut_faces[tet as usize];
            // The child keeping `a` spans the fraction t of the edge, so of the volume.
            let (mut keep_a, mut keep_b) = (parent, parent);
            keep_a[ib] = q;
            keep_b[ia] = q;
            let mass_a = mass * t;
            model.set_tet(tet, keep_a);
            model.tet_mass[tet as usize] = mass_a;
            model.tet_cut_faces[tet as usize] = flags & !(1 << ia);
            let other = model.push_tet(keep_b, mass - mass_a, flags & !(1 << ib));
            out.touched_tets.push(tet);
            out.touched_tets.push(other);
        }
    }
    out.touched_tets.sort_unstable();
    out.touched_tets.dedup();
    out
}

/// Axes held by a node created on edge `a`–`b`: all of them between two pinned nodes;
/// otherwise those both ends hold *and* along which the edge does not extend (a node on an
/// edge lying in a held surface stays in it; a node inside the body, e.g. on an edge
/// through the plate's thickness, is free along it).
pub(crate) fn inherited_axes(model: &MassSpringModel, a: usize, b: usize) -> AxisMask {
    let both = model.fixed[a].intersection(model.fixed[b]);
    if both.is_pinned() {
        return AxisMask::ALL;
    }
    let e = model.reference[b] - model.reference[a];
    let tol = 1e-9 * e.length();
    let mut mask = AxisMask::NONE;
    for (k, axis) in [AxisMask::X, AxisMask::Y, AxisMask::Z]
        .into_iter()
        .enumerate()
    {
        if both.intersection(axis) == axis && e[k].abs() <= tol {
            mask = mask.union(axis);
        }
    }
    mask
}
