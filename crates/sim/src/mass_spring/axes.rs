//! Per-node fixed axes: a node can be held in x, y and/or z (e.g. "surface nodes fixed in
//! the depth direction", PHYSICS.md §2.6).

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A set of coordinate axes along which a node may not move.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct AxisMask(pub u8);

impl AxisMask {
    /// No axis held: the node is free.
    pub const NONE: AxisMask = AxisMask(0);
    /// Held along x.
    pub const X: AxisMask = AxisMask(1);
    /// Held along y.
    pub const Y: AxisMask = AxisMask(2);
    /// Held along z.
    pub const Z: AxisMask = AxisMask(4);
    /// Held along every axis: the node is pinned.
    pub const ALL: AxisMask = AxisMask(7);

    /// The union of two masks.
    pub fn union(self, other: AxisMask) -> AxisMask {
        AxisMask(self.0 | other.0)
    }

    /// The axes held by both masks (a node created on an edge inherits this).
    pub fn intersection(self, other: AxisMask) -> AxisMask {
        AxisMask(self.0 & other.0)
    }

    /// Whether every axis is held.
    pub fn is_pinned(self) -> bool {
        self.0 & 7 == 7
    }

    /// `v` with the held components set to zero.
    pub fn free_part(self, v: DVec3) -> DVec3 {
        DVec3::new(
            if self.0 & 1 != 0 { 0.0 } else { v.x },
            if self.0 & 2 != 0 { 0.0 } else { v.y },
            if self.0 & 4 != 0 { 0.0 } else { v.z },
        )
    }

    /// Whether moving by `d` keeps every held coordinate (within `tol`).
    pub fn allows(self, d: DVec3, tol: f64) -> bool {
        (d - self.free_part(d)).abs().max_element() <= tol
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_zero_held_components() {
        let m = AxisMask::Z.union(AxisMask::X);
        assert_eq!(m.free_part(DVec3::ONE), DVec3::new(0.0, 1.0, 0.0));
        assert!(m.allows(DVec3::new(0.0, 3.0, 0.0), 0.0));
        assert!(!m.allows(DVec3::new(0.0, 3.0, 1e-3), 1e-6));
        assert_eq!(m.intersection(AxisMask::Z), AxisMask::Z);
        assert!(AxisMask::ALL.is_pinned() && !m.is_pinned());
    }
}
