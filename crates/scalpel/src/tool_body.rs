//! The non-cutting body as a parry3d compound of cuboids (the tool keeps it for distance
//! queries outside the solver: placement checks, tests against the solver's own box distance).
//!
//! parry3d 0.31 is built on `glamx` (glam 0.33), not nalgebra, while this workspace uses
//! glam 0.34: values cross the boundary as plain `f32` components.

use glam::Vec3;
use incise_sim::contact::ToolBox;
use parry3d::math::{Pose, Rotation, Vector};
use parry3d::shape::{Compound, Cuboid, SharedShape};

/// A workspace (glam 0.34) vector as a parry3d vector.
pub(crate) fn to_parry(v: Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// The compound of the boxes (at least one: tool validation requires it).
pub(crate) fn compound(boxes: &[ToolBox]) -> Compound {
    let parts = boxes
        .iter()
        .map(|b| {
            let q = b.rotation;
            let pose =
                Pose::from_parts(to_parry(b.centre), Rotation::from_xyzw(q.x, q.y, q.z, q.w));
            (
                pose,
                SharedShape::new(Cuboid::new(to_parry(b.half_extents))),
            )
        })
        .collect();
    Compound::new(parts)
}
