//! A tet's packed data in colour order, as the CPU kernels (scalar and lanes) read it.

use super::neo_hookean::TetTerms;

/// Packed per-tet data in colour order: what one projection reads.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TetSlot {
    pub(crate) nodes: [u32; 4],
    pub(crate) terms: TetTerms,
    pub(crate) live: bool,
}
