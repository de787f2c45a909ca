//! Host mirrors of the Newton kernels' uniform and buffer layouts
//! (`gpu/newton/shaders/newton_common.wgsl`, byte for byte and index for index).

use bytemuck::{Pod, Zeroable};

/// `Newton` (uniform, 64 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct NewtonUniform {
    pub node_count: u32,
    pub slot_count: u32,
    pub coarse_nodes: u32,
    pub max_products: u32,
    pub inv_h2: f32,
    pub mu: f32,
    pub lambda: f32,
    pub tol2: f32,
    pub fall: [f32; 3],
    pub alpha: f32,
    pub node_groups: u32,
    pub tet_groups: u32,
    pub transpose_at: u32,
    pub pad: u32,
}

/// Byte offset of `alpha` in [`NewtonUniform`] (the line search writes it per trial).
pub(crate) const ALPHA_OFFSET: u64 = 44;

/// Byte offsets of `inv_h2` and `fall` in [`NewtonUniform`] (written when a frame runs
/// at other steps).
pub(crate) const INV_H2_OFFSET: u64 = 16;
pub(crate) const FALL_OFFSET: u64 = 32;

/// Byte offset of `coarse_nodes` in [`NewtonUniform`] (written when a cut rebuilds the
/// coarse grid).
pub(crate) const COARSE_NODES_OFFSET: u64 = 8;

/// Slice of `vecs` holding the trial point (`V_TRIAL`).
pub(crate) const V_TRIAL: u64 = 1;
/// Slice of `vecs` holding the lumped masses (`V_MASS`).
pub(crate) const V_MASS: u64 = 11;
/// Slices of `vecs` (`V_SLICES`).
pub(crate) const V_SLICES: u64 = 12;
/// `vec4` per tet slot in `tet_out` (`TET_STRIDE`).
pub(crate) const TET_STRIDE: u64 = 22;

/// Threads of a node or tet workgroup: one partial sum each.
pub(crate) const GROUP: u32 = 64;

/// Where the partial sums and the solve's state lie in `scratch` (`at_*` in the WGSL).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scratch {
    /// Partial sums of a tet reduction.
    pub tet_groups: usize,
    /// Partial sums of a node reduction.
    pub node_groups: usize,
}

/// State words after the partial sums (`S_*`).
pub(crate) const S_STOP: usize = 0;
/// Non-positive curvature met.
pub(crate) const S_NEG: usize = 1;
/// Products spent.
pub(crate) const S_PRODUCTS: usize = 2;
/// The first `r · z`.
pub(crate) const S_FIRST: usize = 3;
/// Words of state.
pub(crate) const STATE_WORDS: usize = 8;

impl Scratch {
    /// Elastic energy partials.
    pub fn tet_energy(&self) -> std::ops::Range<usize> {
        0..self.tet_groups
    }
    /// `m |u − y|²` partials.
    pub fn inertia(&self) -> std::ops::Range<usize> {
        self.node(0)
    }
    /// `|∇G|²` partials.
    pub fn grad2(&self) -> std::ops::Range<usize> {
        self.node(1)
    }
    /// `r · z` partials (the last preconditioned residual of the solve).
    pub fn rz(&self) -> std::ops::Range<usize> {
        self.node(2)
    }
    /// `∇G · d` partials.
    pub fn slope(&self) -> std::ops::Range<usize> {
        self.node(4)
    }
    /// Per workgroup the largest `|d|²` of a free node (the line search's direction).
    pub fn reach(&self) -> std::ops::Range<usize> {
        self.node(5)
    }
    /// The conjugate gradient's state.
    pub fn state(&self) -> usize {
        self.tet_groups + 6 * self.node_groups
    }
    /// Words in all.
    pub fn len(&self) -> usize {
        self.state() + STATE_WORDS
    }
    /// The k-th node reduction's partials.
    fn node(&self, k: usize) -> std::ops::Range<usize> {
        let at = self.tet_groups + k * self.node_groups;
        at..at + self.node_groups
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The host's constants are the shader's.
    #[test]
    fn constants_match_wgsl() {
        assert_eq!(std::mem::size_of::<NewtonUniform>(), 64);
        assert_eq!(
            std::mem::offset_of!(NewtonUniform, alpha) as u64,
            ALPHA_OFFSET
        );
        assert_eq!(
            std::mem::offset_of!(NewtonUniform, coarse_nodes) as u64,
            COARSE_NODES_OFFSET
        );
        assert_eq!(
            std::mem::offset_of!(NewtonUniform, inv_h2) as u64,
            INV_H2_OFFSET
        );
        assert_eq!(
            std::mem::offset_of!(NewtonUniform, fall) as u64,
            FALL_OFFSET
        );
        let src = include_str!("shaders/newton_common.wgsl");
        for (name, value) in [
            ("V_TRIAL", V_TRIAL as usize),
            ("V_MASS", V_MASS as usize),
            ("V_SLICES", V_SLICES as usize),
            ("TET_STRIDE", TET_STRIDE as usize),
            ("S_STOP", S_STOP),
            ("S_NEG", S_NEG),
            ("S_PRODUCTS", S_PRODUCTS),
            ("S_FIRST", S_FIRST),
        ] {
            let line = format!("const {name}: u32 = {value}u;");
            assert!(src.contains(&line), "newton_common.wgsl lacks `{line}`");
        }
    }
}
