//! A latest-value slot between two threads: the writer replaces the value, the reader
//! takes the newest one. Neither waits for the other beyond swapping a pointer under a
//! lock that is never held across any work (no frame waits for a simulation step).

use std::sync::{Arc, Mutex, PoisonError};

/// The newest value put, shared.
pub struct Latest<T> {
    slot: Mutex<Option<Arc<T>>>,
}

impl<T> Default for Latest<T> {
    fn default() -> Self {
        Latest {
            slot: Mutex::new(None),
        }
    }
}

impl<T> Latest<T> {
    /// Replace the value.
    pub fn put(&self, value: T) {
        let value = Arc::new(value);
        // A poisoned lock only means a thread panicked elsewhere; the slot is a pointer.
        *self.slot.lock().unwrap_or_else(PoisonError::into_inner) = Some(value);
    }

    /// The newest value, if any was put.
    pub fn get(&self) -> Option<Arc<T>> {
        self.slot
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reader_gets_the_newest_value() {
        let l = Latest::default();
        assert!(l.get().is_none());
        l.put(1);
        l.put(2);
        assert_eq!(*l.get().unwrap(), 2);
        assert_eq!(*l.get().unwrap(), 2, "reading does not take it away");
    }
}
