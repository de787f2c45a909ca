//! The dynamic state of a [`MassSpringModel`]: what a step changes (positions, velocities
//! and time), apart from what a cut changes (nodes, tets, springs, masses, reference
//! positions). Saving it every frame and the whole model only after a cut remodelled it
//! makes a rollback cost what a frame changes.

use glam::DVec3;

use super::{MassSpringError, MassSpringModel};

/// Positions, velocities and simulated time of a model, as [`MassSpringModel::save_state`]
/// saved them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DynamicState {
    positions: Vec<DVec3>,
    velocities: Vec<DVec3>,
    time: f64,
}

impl DynamicState {
    /// Nodes the saved state has.
    pub fn node_count(&self) -> usize {
        self.positions.len()
    }
}

impl MassSpringModel {
    /// Copy positions, velocities and time into `into`, reusing its buffers.
    pub fn save_state(&self, into: &mut DynamicState) {
        into.positions.clone_from(&self.positions);
        into.velocities.clone_from(&self.velocities);
        into.time = self.time;
    }

    /// Put back positions, velocities and time saved from this model with the same nodes
    /// (no cut in between); an error, and nothing changed, when the node counts differ.
    pub fn restore_state(&mut self, from: &DynamicState) -> Result<(), MassSpringError> {
        if from.node_count() != self.node_count() {
            return Err(MassSpringError::StateMismatch {
                saved: from.node_count(),
                nodes: self.node_count(),
            });
        }
        self.positions.copy_from_slice(&from.positions);
        self.velocities.copy_from_slice(&from.velocities);
        self.time = from.time;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::TetMesh;
    use crate::generate::block;
    use crate::mass_spring::MassSpringParams;

    fn model() -> MassSpringModel {
        let (mesh, _) =
            TetMesh::from_raw(block(Vec3::ZERO, Vec3::splat(0.1), UVec3::new(2, 2, 1))).unwrap();
        MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap()
    }

    #[test]
    fn a_restored_state_is_the_saved_one_bit_for_bit() {
        let mut m = model();
        let all: Vec<u32> = (0..m.node_count() as u32).collect();
        let mut forces = Vec::new();
        let step = |m: &mut MassSpringModel, forces: &mut Vec<DVec3>| {
            m.gather_forces(&all, forces);
            m.integrate_nodes(1e-4, &all, forces);
        };
        step(&mut m, &mut forces);
        let mut saved = DynamicState::default();
        m.save_state(&mut saved);
        let (x, v, t) = (m.positions().to_vec(), m.velocities().to_vec(), m.time());
        step(&mut m, &mut forces);
        m.set_position(0, DVec3::NAN);
        m.restore_state(&saved).unwrap();
        assert_eq!(m.time().to_bits(), t.to_bits());
        let bits = |p: &[DVec3]| -> Vec<[u64; 3]> {
            p.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
        };
        assert_eq!(bits(m.positions()), bits(&x));
        assert_eq!(bits(m.velocities()), bits(&v));
    }

    #[test]
    fn a_state_of_another_node_count_is_refused() {
        let mut m = model();
        let saved = DynamicState::default();
        assert!(matches!(
            m.restore_state(&saved),
            Err(MassSpringError::StateMismatch { saved: 0, .. })
        ));
    }
}
