//! The sweep's copy of the nodes (issue 35, item 3): each node's displacement and inverse
//! mass in one 16-byte record, so a SIMD lane reads a node with one aligned load and
//! writes it back with one store, where the solver's own arrays (`u` of 12 bytes a node,
//! `inv_mass` apart) took three loads and two stores and the shuffles to join them.
//!
//! The records are filled from `u` and `inv_mass` before a sweep and `u` is read back
//! from them after it (both shared by the solver's team); nothing else reads them, so
//! the solver's state stays `u`.

use glam::Vec3;

use crate::thread_team::{ThreadTeam, for_each_part, part_count};

/// Nodes per part of a fill or read-back shared by the team.
const PART_NODES: usize = 1024;

/// One node as the sweep reads it: displacement, then inverse mass.
#[repr(C, align(16))]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct NodeRecord {
    /// Displacement from rest, m.
    pub u: Vec3,
    /// Inverse mass, 1/kg (0: the node does not move).
    pub w: f32,
}

/// Fill `records` (resized to the node count) from the displacements and inverse masses.
pub(crate) fn fill(
    team: Option<&ThreadTeam>,
    records: &mut Vec<NodeRecord>,
    u: &[Vec3],
    inv_mass: &[f32],
) {
    assert_eq!(
        u.len(),
        inv_mass.len(),
        "a displacement and a mass per node"
    );
    records.resize(u.len(), NodeRecord::default());
    let parts = part_count(team, u.len(), PART_NODES);
    for_each_part(team, records, parts, |first, part| {
        let (u, w) = (&u[first..first + part.len()], &inv_mass[first..]);
        for ((r, u), w) in part.iter_mut().zip(u).zip(w) {
            *r = NodeRecord { u: *u, w: *w };
        }
    });
}

/// Read the displacements back from `records` (one per node).
pub(crate) fn read_back(team: Option<&ThreadTeam>, records: &[NodeRecord], u: &mut [Vec3]) {
    assert_eq!(u.len(), records.len(), "a record per node");
    let parts = part_count(team, u.len(), PART_NODES);
    for_each_part(team, u, parts, |first, part| {
        for (u, r) in part.iter_mut().zip(&records[first..]) {
            *u = r.u;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Filled and read back by a team of two in several parts, every node's record holds
    /// its own displacement and mass, and each displacement comes back from its own
    /// record. Broken on purpose once (each part's read-back starting at record 0):
    /// fails.
    #[test]
    fn records_hold_each_nodes_values_in_any_parts() {
        let team = ThreadTeam::new(2).expect("a team of two");
        let n = 5 * PART_NODES + 37;
        let u: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(i as f32, -(i as f32), 0.5))
            .collect();
        let w: Vec<f32> = (0..n).map(|i| 1.0 / (1 + i % 7) as f32).collect();
        for team in [None, Some(&team)] {
            let mut records = vec![NodeRecord::default(); 3];
            fill(team, &mut records, &u, &w);
            assert_eq!(records.len(), n);
            for (i, r) in records.iter().enumerate() {
                assert_eq!((r.u, r.w), (u[i], w[i]), "record {i}");
            }
            for r in &mut records {
                r.u *= 2.0;
            }
            let mut back = vec![Vec3::ZERO; n];
            read_back(team, &records, &mut back);
            for (i, b) in back.iter().enumerate() {
                assert_eq!(*b, 2.0 * u[i], "node {i}");
            }
        }
    }
}
