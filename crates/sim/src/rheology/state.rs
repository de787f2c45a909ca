//! The dynamic state of a [`RheologyBody`]: positions, velocities, the edges' Voigt ratios
//! and the time, all a step changes (materials, edges and masses stay). Saving it each
//! frame instead of cloning the body keeps a rollback's cost to what a frame changes.

use super::{RheologyBody, RheologyError};

/// A body's positions, velocities, ratios and time, as [`RheologyBody::save_state`] saved
/// them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RheologyState {
    values: Vec<f64>,
    time: f64,
}

impl RheologyBody {
    /// Copy the dynamic state into `into`, reusing its buffer.
    pub fn save_state(&self, into: &mut RheologyState) {
        into.values.clone_from(&self.state);
        into.time = self.time;
    }

    /// Put back a state saved from this body; an error, and nothing changed, when it has
    /// another length.
    pub fn restore_state(&mut self, from: &RheologyState) -> Result<(), RheologyError> {
        if from.values.len() != self.state.len() {
            return Err(RheologyError::StateMismatch {
                saved: from.values.len(),
                values: self.state.len(),
            });
        }
        self.state.copy_from_slice(&from.values);
        self.time = from.time;
        Ok(())
    }
}
