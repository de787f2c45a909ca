//! What a body's state is, for checking that a replay (a soak's next cut) or a rollback
//! reproduces it bit for bit: each method's own result in words and a hash of the bits it
//! is judged by.

use std::collections::hash_map::DefaultHasher;
use std::hash::Hasher;

use glam::DVec3;
use serde::Serialize;

/// A body's result now, in its method's own terms.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Outcome {
    /// The result in words, e.g. "412 tets released", "1410 nodes, 3721 tets".
    pub summary: String,
    /// A hash of the bits the method's result is judged by (XPBD: the released tets; Nakao:
    /// the whole model; rheology: positions, velocities, Voigt ratios and time).
    pub hash: u64,
    /// Tets released so far (XPBD only).
    pub released: Option<usize>,
}

impl Outcome {
    /// The hash as 16 hex digits.
    pub fn hash_hex(&self) -> String {
        format!("{:016x}", self.hash)
    }
}

/// A hasher of simulation state bits: the same bits give the same hash in every run of a
/// build (std's SipHash with its fixed keys).
#[derive(Debug, Default)]
pub struct StateHash(DefaultHasher);

impl StateHash {
    /// A hasher over nothing yet.
    pub fn new() -> StateHash {
        StateHash::default()
    }

    /// Add integers.
    pub fn ints(&mut self, values: impl IntoIterator<Item = u64>) -> &mut StateHash {
        for v in values {
            self.0.write_u64(v);
        }
        self
    }

    /// Add the bits of numbers.
    pub fn reals(&mut self, values: impl IntoIterator<Item = f64>) -> &mut StateHash {
        self.ints(values.into_iter().map(f64::to_bits))
    }

    /// Add the bits of vectors.
    pub fn vectors<'a>(&mut self, values: impl IntoIterator<Item = &'a DVec3>) -> &mut StateHash {
        self.reals(values.into_iter().flat_map(|v| v.to_array()))
    }

    /// The hash of everything added.
    pub fn finish(&self) -> u64 {
        self.0.finish()
    }
}
