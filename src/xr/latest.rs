//! A latest-value slot between two threads: the writer replaces the value, the reader
//! takes the newest one. The writer never waits for the reader beyond swapping a pointer
//! under a lock that is never held across any work (no frame waits for a simulation
//! step); a reader with nothing to do may sleep until a value it wants is put.

use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// The newest value put, shared.
pub struct Latest<T> {
    /// The newest value and when it was put.
    slot: Mutex<Option<(Arc<T>, Instant)>>,
    /// Signalled on every put.
    put: Condvar,
}

impl<T> Default for Latest<T> {
    fn default() -> Self {
        Latest {
            slot: Mutex::new(None),
            put: Condvar::new(),
        }
    }
}

impl<T> Latest<T> {
    /// Replace the value.
    pub fn put(&self, value: T) {
        let value = Arc::new(value);
        // A poisoned lock only means a thread panicked elsewhere; the slot is a pointer.
        *self.slot.lock().unwrap_or_else(PoisonError::into_inner) = Some((value, Instant::now()));
        self.put.notify_all();
    }

    /// How long ago the newest value was put (`None`: none yet).
    pub fn age(&self) -> Option<Duration> {
        let slot = self.slot.lock().unwrap_or_else(PoisonError::into_inner);
        slot.as_ref().map(|(_, at)| at.elapsed())
    }

    /// Sleep until the newest value is one `wanted` accepts or `timeout` has passed; the
    /// newest value then.
    pub fn wait_for(&self, timeout: Duration, wanted: impl Fn(&T) -> bool) -> Option<Arc<T>> {
        let slot = self.slot.lock().unwrap_or_else(PoisonError::into_inner);
        let (slot, _) = self
            .put
            .wait_timeout_while(slot, timeout, |v| {
                !v.as_ref().is_some_and(|(v, _)| wanted(v))
            })
            .unwrap_or_else(PoisonError::into_inner);
        slot.as_ref().map(|(v, _)| Arc::clone(v))
    }

    /// The newest value, if any was put.
    pub fn get(&self) -> Option<Arc<T>> {
        let slot = self.slot.lock().unwrap_or_else(PoisonError::into_inner);
        slot.as_ref().map(|(v, _)| Arc::clone(v))
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

    #[test]
    fn the_age_is_the_time_since_the_newest_put() {
        let l = Latest::default();
        assert!(l.age().is_none());
        l.put(1);
        std::thread::sleep(Duration::from_millis(20));
        let old = l.age().unwrap();
        assert!(old >= Duration::from_millis(20), "{old:?}");
        l.put(2);
        assert!(l.age().unwrap() < old, "a put does not renew the age");
    }

    #[test]
    fn a_waiting_reader_wakes_for_the_value_it_wants() {
        let l = Arc::new(Latest::default());
        l.put(1);
        // Nothing it wants: it waits out the timeout and gets the newest value.
        let t0 = std::time::Instant::now();
        assert_eq!(
            *l.wait_for(Duration::from_millis(20), |&v| v > 1).unwrap(),
            1
        );
        assert!(t0.elapsed() >= Duration::from_millis(20));
        // Put from another thread: it wakes long before its timeout.
        let writer = Arc::clone(&l);
        let t0 = std::time::Instant::now();
        let put = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(10));
            writer.put(2);
        });
        assert_eq!(*l.wait_for(Duration::from_secs(10), |&v| v > 1).unwrap(), 2);
        assert!(t0.elapsed() < Duration::from_secs(10));
        put.join().unwrap();
    }
}
