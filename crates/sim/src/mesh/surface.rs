//! Triangle surfaces (skin meshes, boundaries exported as OBJ).

use glam::Vec3;

/// An indexed triangle surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriSurface {
    /// Vertex positions, metres.
    pub positions: Vec<Vec3>,
    /// Triangles as 0-based vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}
