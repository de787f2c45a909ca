//! Choosing sets of nodes (for pins and grabs) by box, plane side or index list.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A rule that picks nodes by their rest position or index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum NodeSelection {
    /// Nodes inside the axis-aligned box `[min, max]` (metres, inclusive).
    Box {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// Nodes on the side of the plane through `point` that `normal` points to (inclusive).
    PlaneSide {
        /// A point on the plane.
        point: Vec3,
        /// Normal pointing to the selected side (need not be unit length).
        normal: Vec3,
    },
    /// Explicit 0-based node indices.
    Indices(Vec<u32>),
}

/// Why a selection is unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SelectionError {
    /// The rule matched no node: almost certainly a wrong coordinate or unit.
    #[error("{0} selects no node (mesh bounds {1:?} .. {2:?})")]
    Empty(String, Vec3, Vec3),
    /// An index is past the node count.
    #[error("node index {index} is out of range (the mesh has {count} nodes)")]
    OutOfRange {
        /// The index.
        index: u32,
        /// Node count.
        count: usize,
    },
    /// The plane normal is zero or not finite.
    #[error("plane normal {0} must be a non-zero vector")]
    BadNormal(Vec3),
}

impl NodeSelection {
    /// Indices of the selected nodes, ascending; an error when none is selected.
    pub fn select(&self, positions: &[Vec3]) -> Result<Vec<u32>, SelectionError> {
        let picked: Vec<u32> = match self {
            NodeSelection::Box { min, max } => {
                filter(positions, |p| p.cmpge(*min).all() && p.cmple(*max).all())
            }
            NodeSelection::PlaneSide { point, normal } => {
                if !(normal.is_finite() && normal.length_squared() > 0.0) {
                    return Err(SelectionError::BadNormal(*normal));
                }
                // A tolerance of 1 µm keeps nodes lying on the plane despite rounding.
                let n = normal.normalize();
                filter(positions, |p| (p - *point).dot(n) >= -1e-6)
            }
            NodeSelection::Indices(list) => {
                if let Some(&index) = list.iter().find(|&&i| i as usize >= positions.len()) {
                    return Err(SelectionError::OutOfRange {
                        index,
                        count: positions.len(),
                    });
                }
                let mut v = list.clone();
                v.sort_unstable();
                v.dedup();
                v
            }
        };
        if picked.is_empty() {
            let (lo, hi) = crate::mesh::bounds(positions);
            return Err(SelectionError::Empty(format!("{self:?}"), lo, hi));
        }
        Ok(picked)
    }
}

fn filter(positions: &[Vec3], keep: impl Fn(Vec3) -> bool) -> Vec<u32> {
    positions
        .iter()
        .enumerate()
        .filter(|(_, p)| keep(**p))
        .map(|(i, _)| i as u32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_plane_pick_expected_nodes() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)];
        let b = NodeSelection::Box {
            min: Vec3::splat(-0.5),
            max: Vec3::new(1.0, 0.5, 0.5),
        };
        assert_eq!(b.select(&p).unwrap(), vec![0, 1]);
        let s = NodeSelection::PlaneSide {
            point: Vec3::X,
            normal: Vec3::X,
        };
        assert_eq!(s.select(&p).unwrap(), vec![1, 2]);
    }

    #[test]
    fn empty_and_out_of_range_are_errors() {
        let p = [Vec3::ZERO];
        let b = NodeSelection::Box {
            min: Vec3::ONE,
            max: Vec3::splat(2.0),
        };
        assert!(matches!(b.select(&p), Err(SelectionError::Empty(..))));
        assert!(matches!(
            NodeSelection::Indices(vec![3]).select(&p),
            Err(SelectionError::OutOfRange { index: 3, count: 1 })
        ));
    }
}
