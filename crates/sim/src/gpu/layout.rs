//! Host mirrors of the WGSL structs in `gpu/shaders/common.wgsl` (byte-for-byte layouts).

use bytemuck::{Pod, Zeroable};

/// `Params` (uniform, 80 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct Params {
    pub gravity: [f32; 3],
    pub h: f32,
    pub inv_h: f32,
    pub keep: f32,
    pub gamma: f32,
    pub mu: f32,
    pub threshold: f32,
    pub node_count: u32,
    pub slot_count: u32,
    pub grab_count: u32,
    pub mode: u32,
    pub sphere_count: u32,
    pub box_count: u32,
    pub friction: f32,
    pub reach: f32,
    pub lambda: f32,
    pub pair: u32,
    pub measure: u32,
}

/// `Step` (uniform, 16 bytes, bound at 256-byte aligned offsets).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct Step {
    pub first: u32,
    pub count: u32,
    pub substep: u32,
    pub pad: u32,
}

/// `TetRest` (storage, 48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct TetRest {
    pub c0: [f32; 4],
    pub c1: [f32; 4],
    pub c2: [f32; 4],
}

/// Node kinds as the kernels encode them.
pub(crate) const KIND_FREE: u32 = 0;
/// Pinned node.
pub(crate) const KIND_PINNED: u32 = 1;
/// Retired node.
pub(crate) const KIND_RETIRED: u32 = 2;
/// First grabbed kind: grab `k` is `KIND_GRAB0 + k`.
pub(crate) const KIND_GRAB0: u32 = 3;

/// Stride between `Step` records in the step uniform buffer.
pub(crate) const STEP_STRIDE: u64 = 256;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_match_wgsl() {
        assert_eq!(std::mem::size_of::<Params>(), 80);
        assert_eq!(std::mem::size_of::<Step>(), 16);
        assert_eq!(std::mem::size_of::<TetRest>(), 48);
    }
}
