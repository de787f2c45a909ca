//! Unsynchronised shared access to node positions for the coloured parallel projection.

use glam::Vec3;

/// A view of the position array that several threads read and write at once.
///
/// Sound only under graph colouring: within one colour no two tets share a node, so every
/// node is touched by at most one thread per colour pass (PHYSICS.md §1.2, parallel form).
pub(crate) struct SharedNodes {
    ptr: *mut Vec3,
    len: usize,
}

// SAFETY: access is partitioned by the colouring; see the type's doc.
unsafe impl Sync for SharedNodes {}
unsafe impl Send for SharedNodes {}

impl SharedNodes {
    pub(super) fn new(x: &mut [Vec3]) -> Self {
        SharedNodes {
            ptr: x.as_mut_ptr(),
            len: x.len(),
        }
    }

    /// Number of nodes.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The first node's address (reads and writes through it follow the colouring too).
    pub(super) fn as_ptr(&self) -> *mut Vec3 {
        self.ptr
    }

    /// Read node `i`.
    ///
    /// # Safety
    /// No other thread may write node `i` during this colour pass.
    #[inline]
    pub(super) unsafe fn get(&self, i: u32) -> Vec3 {
        assert!((i as usize) < self.len);
        // SAFETY: in bounds (checked); exclusive per colour by the caller's contract.
        unsafe { *self.ptr.add(i as usize) }
    }

    /// Write node `i`.
    ///
    /// # Safety
    /// No other thread may read or write node `i` during this colour pass.
    #[inline]
    pub(super) unsafe fn set(&self, i: u32, v: Vec3) {
        assert!((i as usize) < self.len);
        // SAFETY: as for `get`.
        unsafe { *self.ptr.add(i as usize) = v }
    }
}
