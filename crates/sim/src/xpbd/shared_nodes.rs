//! Unsynchronised shared access to the sweep's node records for the coloured parallel
//! projection.

use glam::Vec3;

use super::node_records::NodeRecord;

/// A view of the node records ([`NodeRecord`]) that several threads read and write at once.
///
/// Sound only under graph colouring: within one colour no two tets share a node, so every
/// node is touched by at most one thread per colour pass (PHYSICS.md §1.2, parallel form).
pub(crate) struct SharedNodes {
    ptr: *mut NodeRecord,
    len: usize,
}

// SAFETY: access is partitioned by the colouring; see the type's doc.
unsafe impl Sync for SharedNodes {}
unsafe impl Send for SharedNodes {}

impl SharedNodes {
    pub(super) fn new(records: &mut [NodeRecord]) -> Self {
        SharedNodes {
            ptr: records.as_mut_ptr(),
            len: records.len(),
        }
    }

    /// Number of nodes.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The first record's address (reads and writes through it follow the colouring too).
    pub(super) fn as_ptr(&self) -> *mut NodeRecord {
        self.ptr
    }

    /// Read node `i`'s displacement and inverse mass.
    ///
    /// # Safety
    /// No other thread may write node `i` during this colour pass.
    #[inline]
    pub(super) unsafe fn get(&self, i: u32) -> (Vec3, f32) {
        assert!((i as usize) < self.len);
        // SAFETY: in bounds (checked); exclusive per colour by the caller's contract.
        let r = unsafe { *self.ptr.add(i as usize) };
        (r.u, r.w)
    }

    /// Write node `i`'s displacement.
    ///
    /// # Safety
    /// No other thread may read or write node `i` during this colour pass.
    #[inline]
    pub(super) unsafe fn set(&self, i: u32, v: Vec3) {
        assert!((i as usize) < self.len);
        // SAFETY: as for `get`.
        unsafe { (*self.ptr.add(i as usize)).u = v }
    }
}
