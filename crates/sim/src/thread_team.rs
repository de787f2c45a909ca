//! A fixed team of threads that run the parts of one job together, many times a frame
//! (issue 35, item 1: a sweep that synchronises a handful of times should pay a handful of
//! cache-line round trips, not a thread wake-up each).
//!
//! A rayon pool puts an idle worker to sleep within microseconds, and waking it costs a
//! system call and, on a virtual machine, a halted virtual CPU brought back: 16–52 µs
//! measured on the 2-core guest (docs/performance.md, "The sweep's threads as a team"),
//! paid after every serial gap of a sweep (prediction, contacts, velocities). A team
//! member instead waits for the next job for [`SPIN`] after each one (spinning, then
//! yielding its core between looks), so the gaps inside a frame cost it nothing, and
//! sleeps once the frame is over.
//!
//! A job is cut into parts that do not depend on each other. Each member has a home range
//! of them (the same data job after job, so it stays in that core's cache) and claims its
//! parts one at a time, then any the others have not claimed: a member the system has
//! descheduled leaves its parts to the others instead of stalling the job (as rayon's work
//! stealing does). Which member runs a part does not change what the part computes, so
//! results never depend on timing.

use std::cell::UnsafeCell;
use std::ops::Range;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

/// How long an idle member waits for the next job before it sleeps: longer than the
/// serial gaps inside a frame (tens of µs), far shorter than a frame.
pub const SPIN: Duration = Duration::from_micros(250);

/// How long a waiting member spins without yielding its core: longer than the gaps
/// between a sweep's passes, short enough that on a busy machine (or with more threads
/// than cores) the thread it waits for gets the core soon.
const SPIN_ALONE: Duration = Duration::from_micros(20);

/// Spins between looks at the clock.
const SPINS_PER_LOOK: u32 = 64;

/// A job with its lifetime erased: valid while its epoch has an unfinished part
/// ([`ThreadTeam::run`] returns only when every part is done).
type Job = *const (dyn Fn(usize) + Sync);

/// A claim word: the job's epoch in the high half, then the end of a member's home range
/// of parts and its next unclaimed part (16 bits each), so that one load tells a member
/// all it needs.
fn claim_word(epoch: u32, end: u16, next: u16) -> u64 {
    (epoch as u64) << 32 | (end as u64) << 16 | next as u64
}

/// An atomic alone on its cache line, so that one member's counting does not evict
/// another's.
#[repr(align(128))]
struct Line<T>(T);

/// What the caller and the workers share.
struct Shared {
    /// The current job's epoch, published last: what idle workers watch.
    epoch: AtomicU32,
    /// Per member, the [`claim_word`] of its home range of the current job's parts: a
    /// part is claimed by advancing the range's next part while the word still names the
    /// job's epoch. A member claims its own range first (the same part of the data each
    /// job, in its own cache), then the others'.
    claims: Vec<Line<AtomicU64>>,
    /// The current job (written by the caller only while no part of a job is claimable
    /// or running).
    job: UnsafeCell<Option<Job>>,
    /// Per member, parts of the current job it has done.
    done: Vec<Line<AtomicUsize>>,
    /// A part of the current job panicked.
    panicked: AtomicBool,
    /// The team is being dropped.
    stop: AtomicBool,
    /// Per worker, whether it is (about to be) parked.
    sleeping: Vec<AtomicBool>,
}

// SAFETY: `job` is written by the caller only when every part of the previous job is
// done and before the next epoch is published (Release); a worker reads it only after
// claiming a part of that epoch, which keeps the job unfinished until the part is done.
// Everything else is atomic.
unsafe impl Sync for Shared {}
// SAFETY: as above; the job pointer is only dereferenced under that protocol.
unsafe impl Send for Shared {}

impl Shared {
    /// The shared state of a team of `members`, no job published.
    fn new(members: usize) -> Self {
        Shared {
            epoch: AtomicU32::new(0),
            claims: (0..members).map(|_| Line(AtomicU64::new(0))).collect(),
            job: UnsafeCell::new(None),
            done: (0..members).map(|_| Line(AtomicUsize::new(0))).collect(),
            panicked: AtomicBool::new(false),
            stop: AtomicBool::new(false),
            sleeping: (1..members).map(|_| AtomicBool::new(false)).collect(),
        }
    }

    /// Publish `job` of `parts` parts (at most `u16::MAX`) as `epoch`, each member's home
    /// range its [`share`] of the parts.
    ///
    /// # Safety
    /// Every part of the previous job is done, and `job` stays valid until all of this
    /// one's are.
    unsafe fn publish(&self, job: Job, epoch: u32, parts: usize) {
        // SAFETY: the caller's contract: no member reads the job now.
        unsafe { *self.job.get() = Some(job) };
        let size = self.claims.len();
        for (m, (claims, done)) in self.claims.iter().zip(&self.done).enumerate() {
            let home = share(parts, m, size);
            let word = claim_word(epoch, home.end as u16, home.start as u16);
            claims.0.store(word, Ordering::SeqCst);
            done.0.store(0, Ordering::SeqCst);
        }
        self.epoch.store(epoch, Ordering::SeqCst);
    }

    /// Member `m`'s turn at `epoch`'s job: claim and run parts, its home range's first,
    /// until none is left.
    fn run_parts(&self, m: usize, epoch: u32) {
        let size = self.claims.len();
        for range in (0..size).map(|j| (m + j) % size) {
            while let Some(part) = self.claim(range, epoch) {
                // SAFETY: the claimed part is not done, so the job of `epoch` is still
                // the current one and alive (see the impls above).
                let job = unsafe { (*self.job.get()).expect("a job is published with its epoch") };
                // SAFETY: as above.
                let result = panic::catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(part) }));
                if result.is_err() {
                    self.panicked.store(true, Ordering::SeqCst);
                }
                self.done[m].0.fetch_add(1, Ordering::Release);
            }
        }
    }

    /// The next unclaimed part of `epoch`'s job in member `range`'s home range, claimed;
    /// `None` when all are claimed or the job is over.
    fn claim(&self, range: usize, epoch: u32) -> Option<usize> {
        let claims = &self.claims[range].0;
        let mut word = claims.load(Ordering::Acquire);
        loop {
            let (end, next) = ((word >> 16) as u16, word as u16);
            if (word >> 32) as u32 != epoch || next >= end {
                return None;
            }
            let claimed = claim_word(epoch, end, next + 1);
            match claims.compare_exchange_weak(word, claimed, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) => return Some(next as usize),
                Err(now) => word = now,
            }
        }
    }

    /// Parts of the current job done, by all members.
    fn parts_done(&self) -> usize {
        self.done.iter().map(|d| d.0.load(Ordering::Acquire)).sum()
    }
}

/// Member `member`'s contiguous share of `len` items split among `size` members: the
/// shares differ in length by at most one and together are `0..len`, in member order.
pub fn share(len: usize, member: usize, size: usize) -> Range<usize> {
    len * member / size..len * (member + 1) / size
}

/// `items` cut into `parts` contiguous parts ([`share`]) of whole units of `unit` items,
/// in order.
fn split_parts<T>(mut items: &mut [T], unit: usize, parts: usize) -> Vec<&mut [T]> {
    let units = items.len() / unit;
    let mut split = Vec::with_capacity(parts);
    for p in 0..parts {
        let (mine, rest) = items.split_at_mut(share(units, p, parts).len() * unit);
        split.push(mine);
        items = rest;
    }
    split
}

/// Most parts a pass is cut into per member: a few, so that the members even out.
const PARTS_PER_MEMBER: usize = 4;

/// Parts to cut a pass over `len` items into: one without a team, else one per
/// `min_part` items, at most `PARTS_PER_MEMBER` per member.
pub fn part_count(team: Option<&ThreadTeam>, len: usize, min_part: usize) -> usize {
    match team {
        Some(t) => (len / min_part.max(1)).clamp(1, PARTS_PER_MEMBER * t.size()),
        None => 1,
    }
}

/// `f(first, part)` for each of `parts` contiguous parts of `items` (`first`: the index of
/// the part's first item), shared by the members of `team`, or in one part on this thread
/// without one.
pub fn for_each_part<T: Send>(
    team: Option<&ThreadTeam>,
    items: &mut [T],
    parts: usize,
    f: impl Fn(usize, &mut [T]) + Sync,
) {
    for_each_part_of_units(team, items, 1, parts, f);
}

/// [`for_each_part`] with the parts cut between units of `unit` items (`items.len()` a
/// multiple of it); `first` counts units.
pub fn for_each_part_of_units<T: Send>(
    team: Option<&ThreadTeam>,
    items: &mut [T],
    unit: usize,
    parts: usize,
    f: impl Fn(usize, &mut [T]) + Sync,
) {
    assert!(items.len() % unit == 0, "whole units");
    let Some(team) = team.filter(|_| parts > 1) else {
        return f(0, items);
    };
    let units = items.len() / unit;
    let split = split_parts(items, unit, parts);
    run_split(team, split, |p, mine| f(share(units, p, parts).start, mine));
}

/// `f(p, &mut split[p])` for each part `p`, on the members of `team`.
fn run_split<S: Send>(team: &ThreadTeam, split: Vec<S>, f: impl Fn(usize, &mut S) + Sync) {
    // Each part is locked by the one member that claimed it: never contended.
    let split: Vec<Mutex<S>> = split.into_iter().map(Mutex::new).collect();
    team.run(split.len(), |p| {
        let mut mine = split[p]
            .lock()
            .expect("a part is locked by its member only");
        f(p, &mut mine);
    });
}

/// `f(i, &mut items[i])` for every item, in parts of at least `min_part` items
/// ([`part_count`]) shared by the members of `team`, or all on this thread without one.
pub fn for_each_item<T: Send>(
    team: Option<&ThreadTeam>,
    items: &mut [T],
    min_part: usize,
    f: impl Fn(usize, &mut T) + Sync,
) {
    let parts = part_count(team, items.len(), min_part);
    for_each_part(team, items, parts, |first, part| {
        for (k, item) in part.iter_mut().enumerate() {
            f(first + k, item);
        }
    });
}

/// `f(i, &mut a[i], &mut b[i])` for every `i` (the two of one length), as
/// [`for_each_zip3`].
pub fn for_each_zip2<A: Send, B: Send>(
    team: Option<&ThreadTeam>,
    (a, b): (&mut [A], &mut [B]),
    min_part: usize,
    f: impl Fn(usize, &mut A, &mut B) + Sync,
) {
    // A third array of nothing: `()` takes no memory.
    let mut nothing = vec![(); a.len()];
    for_each_zip3(team, (a, b, &mut nothing), min_part, |i, a, b, _| {
        f(i, a, b)
    });
}

/// `f(i, &mut a[i], &mut b[i], &mut c[i])` for every `i` (the three of one length), in
/// parts of at least `min_part` items ([`part_count`]) shared by the members of `team`,
/// or all on this thread without one.
pub fn for_each_zip3<A: Send, B: Send, C: Send>(
    team: Option<&ThreadTeam>,
    (a, b, c): (&mut [A], &mut [B], &mut [C]),
    min_part: usize,
    f: impl Fn(usize, &mut A, &mut B, &mut C) + Sync,
) {
    assert!(
        a.len() == b.len() && b.len() == c.len(),
        "arrays of one length"
    );
    let run = |start: usize, a: &mut [A], b: &mut [B], c: &mut [C]| {
        let items = a.iter_mut().zip(b.iter_mut()).zip(c.iter_mut());
        for (k, ((a, b), c)) in items.enumerate() {
            f(start + k, a, b, c);
        }
    };
    let parts = part_count(team, a.len(), min_part);
    let Some(team) = team.filter(|_| parts > 1) else {
        return run(0, a, b, c);
    };
    let len = a.len();
    let (a, b, c) = (
        split_parts(a, 1, parts),
        split_parts(b, 1, parts),
        split_parts(c, 1, parts),
    );
    let split: Vec<_> = a.into_iter().zip(b).zip(c).collect();
    run_split(team, split, |p, ((a, b), c)| {
        run(share(len, p, parts).start, a, b, c)
    });
}

/// Threads that run the parts of a job together: [`ThreadTeam::run`].
pub struct ThreadTeam {
    shared: Arc<Shared>,
    workers: Vec<JoinHandle<()>>,
    /// A job is being run (one at a time: a part may not start another).
    busy: AtomicBool,
}

impl ThreadTeam {
    /// A team of `size` members: the caller and `size − 1` new threads.
    pub fn new(size: usize) -> std::io::Result<Self> {
        let workers = size.max(1) - 1;
        let shared = Arc::new(Shared::new(workers + 1));
        let mut team = ThreadTeam {
            shared,
            workers: Vec::with_capacity(workers),
            busy: AtomicBool::new(false),
        };
        for k in 0..workers {
            let shared = Arc::clone(&team.shared);
            let handle = thread::Builder::new()
                .name(format!("incise-team-{}", k + 1))
                .spawn(move || work(&shared, k))?;
            team.workers.push(handle);
        }
        Ok(team)
    }

    /// Members, the caller included.
    pub fn size(&self) -> usize {
        self.workers.len() + 1
    }

    /// Call `f(p)` once for each part `p` in `0..parts`, on whichever members claim
    /// them (this thread among them), and return when all calls have; a panic in any
    /// part is raised here after all have ended. One job at a time: a call from inside a
    /// part, or from another thread during a job, panics.
    pub fn run(&self, parts: usize, f: impl Fn(usize) + Sync) {
        if self.workers.is_empty() || parts <= 1 {
            return (0..parts).for_each(f);
        }
        assert!(parts <= u16::MAX as usize, "at most 65,535 parts a job");
        let busy = self.busy.swap(true, Ordering::Acquire);
        assert!(!busy, "a thread team runs one job at a time");
        let shared = &*self.shared;
        let job: &(dyn Fn(usize) + Sync) = &f;
        // SAFETY: only the lifetime is erased; `job` outlives every use, as this call
        // returns only after every part is done.
        let job: Job = unsafe { std::mem::transmute::<&(dyn Fn(usize) + Sync), Job>(job) };
        let epoch = shared.epoch.load(Ordering::Relaxed).wrapping_add(1);
        // SAFETY: every part of the previous job is done (waited for below), and `busy`
        // keeps any other job out.
        unsafe { shared.publish(job, epoch, parts) };
        for (k, w) in self.workers.iter().enumerate() {
            if shared.sleeping[k].load(Ordering::SeqCst) {
                w.thread().unpark();
            }
        }
        shared.run_parts(0, epoch);
        let mut wait = Patience::new();
        while shared.parts_done() < parts {
            wait.pause();
        }
        let panicked = shared.panicked.swap(false, Ordering::SeqCst);
        self.busy.store(false, Ordering::Release);
        if panicked {
            panic!("a thread-team job panicked in one of its parts");
        }
    }
}

impl Drop for ThreadTeam {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        for w in &self.workers {
            w.thread().unpark();
        }
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
    }
}

/// Worker `k`'s loop: wait for each job, claim and run its parts while any are left.
fn work(shared: &Shared, k: usize) {
    let mut seen = 0;
    while let Some(epoch) = next_epoch(shared, k, seen) {
        seen = epoch;
        shared.run_parts(k + 1, epoch);
    }
}

/// Wait for an epoch after `seen`: [`Patience`] for [`SPIN`], then park until woken.
/// `None` when the team is being dropped.
fn next_epoch(shared: &Shared, k: usize, seen: u32) -> Option<u32> {
    let mut wait = Patience::new();
    loop {
        let epoch = shared.epoch.load(Ordering::Acquire);
        if epoch != seen {
            return Some(epoch);
        }
        if shared.stop.load(Ordering::Acquire) {
            return None;
        }
        if wait.pause() < SPIN {
            continue;
        }
        shared.sleeping[k].store(true, Ordering::SeqCst);
        // Checked again after announcing sleep: a job published in between either sees
        // the flag (and unparks) or is seen here.
        let epoch = shared.epoch.load(Ordering::SeqCst);
        if epoch == seen && !shared.stop.load(Ordering::SeqCst) {
            thread::park();
        }
        shared.sleeping[k].store(false, Ordering::SeqCst);
        wait = Patience::new();
    }
}

/// A wait between looks at a flag: [`SPIN_ALONE`] of spinning, then the core yielded
/// between looks.
struct Patience {
    since: Instant,
    spins: u32,
    waited: Duration,
}

impl Patience {
    /// A wait starting now.
    fn new() -> Self {
        Patience {
            since: Instant::now(),
            spins: 0,
            waited: Duration::ZERO,
        }
    }

    /// Pause before the next look; how long the wait has lasted (as of the last look at
    /// the clock).
    fn pause(&mut self) -> Duration {
        if self.waited >= SPIN_ALONE {
            thread::yield_now();
            self.waited = self.since.elapsed();
            return self.waited;
        }
        std::hint::spin_loop();
        self.spins += 1;
        if self.spins % SPINS_PER_LOOK == 0 {
            self.waited = self.since.elapsed();
        }
        self.waited
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;

    #[test]
    fn every_part_runs_once_a_job() {
        let team = ThreadTeam::new(3).unwrap();
        assert_eq!(team.size(), 3);
        let counts: Vec<AtomicU32> = (0..5).map(|_| AtomicU32::new(0)).collect();
        for round in 0..2_000u32 {
            team.run(counts.len(), |p| {
                counts[p].fetch_add(1, Ordering::Relaxed);
            });
            // Every call has ended when `run` returns.
            for c in &counts {
                assert_eq!(c.load(Ordering::Relaxed), round + 1);
            }
            if round % 500 == 0 {
                // Long enough for the workers to fall asleep: they must wake.
                thread::sleep(SPIN * 4);
            }
        }
    }

    #[test]
    fn the_parts_run_on_several_threads_at_once_and_end_before_the_run() {
        let team = ThreadTeam::new(2).unwrap();
        let caller = thread::current().id();
        let (started, finished) = (AtomicU32::new(0), AtomicU32::new(0));
        let threads = Mutex::new(Vec::new());
        team.run(2, |_| {
            threads.lock().unwrap().push(thread::current().id());
            started.fetch_add(1, Ordering::SeqCst);
            // Each part waits for the other to start: only two threads can finish.
            let since = Instant::now();
            while started.load(Ordering::SeqCst) < 2 {
                assert!(
                    since.elapsed().as_secs() < 20,
                    "the parts never ran together"
                );
                thread::yield_now();
            }
            if thread::current().id() != caller {
                // The worker's part ends well after the caller's.
                thread::sleep(Duration::from_millis(50));
            }
            finished.fetch_add(1, Ordering::SeqCst);
        });
        assert_eq!(
            finished.load(Ordering::SeqCst),
            2,
            "returned before a part ended"
        );
        let threads = threads.into_inner().unwrap();
        assert!(threads[0] != threads[1], "both parts on one thread");
    }

    #[test]
    fn a_member_takes_the_parts_another_has_not_claimed() {
        // A team of three whose other two members never come (descheduled): member 0
        // runs its own parts, then theirs.
        let shared = Shared::new(3);
        let ran = Mutex::new(Vec::new());
        let job = |p: usize| ran.lock().unwrap().push(p);
        let job: &(dyn Fn(usize) + Sync) = &job;
        // SAFETY: no job before; this one outlives its parts (all run below).
        unsafe {
            shared.publish(
                std::mem::transmute::<&(dyn Fn(usize) + Sync), Job>(job),
                1,
                7,
            )
        };
        shared.run_parts(0, 1);
        assert_eq!(shared.parts_done(), 7);
        // Its home range first, in order, then the next members' ranges.
        assert_eq!(*ran.lock().unwrap(), vec![0, 1, 2, 3, 4, 5, 6]);
        shared.run_parts(2, 1);
        assert_eq!(ran.lock().unwrap().len(), 7, "a part ran twice");
    }

    #[test]
    fn a_panic_in_a_part_reaches_the_caller_and_the_team_goes_on() {
        let team = ThreadTeam::new(2).unwrap();
        for _ in 0..20 {
            let caught = panic::catch_unwind(AssertUnwindSafe(|| {
                team.run(4, |p| assert!(p != 3, "part {p} fails on purpose"));
            }));
            assert!(caught.is_err(), "the part's panic was lost");
        }
        let ran = AtomicU32::new(0);
        team.run(4, |_| {
            ran.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(ran.load(Ordering::Relaxed), 4);
    }

    #[test]
    fn the_shares_cover_the_items_once_in_order() {
        for size in 1..5 {
            for len in 0..20 {
                let shares: Vec<_> = (0..size).map(|m| share(len, m, size)).collect();
                let joined: Vec<usize> = shares.iter().cloned().flatten().collect();
                assert_eq!(joined, (0..len).collect::<Vec<_>>(), "{len} items, {size}");
                let (lo, hi) = shares
                    .iter()
                    .map(|r| r.len())
                    .fold((len, 0), |(a, b), n| (a.min(n), b.max(n)));
                assert!(hi - lo <= 1, "{len} items among {size}: {shares:?}");
            }
        }
    }

    #[test]
    fn a_zipped_pass_visits_each_index_once_with_its_items() {
        for size in [1, 2, 3] {
            let team = ThreadTeam::new(size).unwrap();
            let n = 1001;
            let mut a: Vec<usize> = (0..n).collect();
            let mut b = vec![0usize; n];
            let mut c = vec![0u32; n];
            for_each_zip3(Some(&team), (&mut a, &mut b, &mut c), 100, |i, a, b, c| {
                *b = *a * 2 + i;
                *c += 1;
            });
            for i in 0..n {
                assert_eq!((b[i], c[i]), (3 * i, 1), "index {i}, team of {size}");
            }
        }
    }

    #[test]
    fn parts_of_units_keep_their_units_whole() {
        let team = ThreadTeam::new(2).unwrap();
        let mut items: Vec<usize> = vec![0; 3 * 11];
        for_each_part_of_units(Some(&team), &mut items, 3, 4, |first, part| {
            assert_eq!(part.len() % 3, 0, "a part cut a unit");
            for (k, item) in part.iter_mut().enumerate() {
                *item = first * 3 + k;
            }
        });
        assert_eq!(items, (0..33).collect::<Vec<_>>());
    }

    #[test]
    fn a_job_started_inside_a_part_is_refused() {
        let team = ThreadTeam::new(2).unwrap();
        let caught = panic::catch_unwind(AssertUnwindSafe(|| {
            team.run(2, |_| team.run(2, |_| {}));
        }));
        assert!(caught.is_err(), "a nested job ran");
        team.run(2, |_| {});
    }

    #[test]
    fn a_team_of_one_runs_on_the_caller() {
        let team = ThreadTeam::new(1).unwrap();
        let here = thread::current().id();
        team.run(3, |_| assert_eq!(thread::current().id(), here));
    }
}
