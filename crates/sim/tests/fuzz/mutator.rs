//! A small deterministic byte mutator for fuzzing parsers on stable Rust (issue 11):
//! seeded with real files, it flips bits, swaps in hostile numbers and tokens, deletes,
//! duplicates, truncates and splices. Shared by the reader fuzzers of incise-sim and the
//! app (included with `#[path]`).
#![allow(dead_code)]

/// xorshift64* — fast, reproducible, no dependency.
pub struct Rng(u64);

impl Rng {
    /// A generator from a non-zero seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    /// Next 64 random bits.
    pub fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `0..n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Numbers and tokens that break parsers: huge counts, negatives, non-finite floats,
/// section markers, XML fragments.
const TOKENS: &[&str] = &[
    "-1",
    "0",
    "1",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "99999999999999999999",
    "1e39",
    "-1e39",
    "1e-45",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "0x10",
    "1.5",
    " ",
    "\n",
    "\t",
    "$EndNodes",
    "$Elements",
    "$EndElements",
    "$Nodes",
    "CELLS",
    "POINTS",
    "CELL_TYPES",
    "</DataArray>",
    "<Piece NumberOfPoints=\"999999999\" NumberOfCells=\"1\">",
    "\"",
    ">",
    "<",
    "f",
    "v",
    "#",
    "//",
    "(",
    ")",
    "[",
    "]",
    ",",
    ":",
    "Some(",
    "None",
    "true",
];

/// One mutation of `input` (1–4 operations), possibly spliced with `other`.
pub fn mutate(rng: &mut Rng, input: &[u8], other: &[u8]) -> Vec<u8> {
    let mut b = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = b.len();
        match rng.below(9) {
            0 if n > 0 => {
                let i = rng.below(n);
                b[i] ^= 1 << rng.below(8);
            }
            1 if n > 0 => {
                let i = rng.below(n);
                b[i] = b"0123456789 \n-.eE+$<>\"/=(),:"[rng.below(27)];
            }
            2 if n > 0 => {
                let i = rng.below(n);
                let len = 1 + rng.below(16.min(n - i));
                b.drain(i..i + len);
            }
            3 if n > 0 => {
                let i = rng.below(n);
                let len = 1 + rng.below(64.min(n - i));
                let chunk = b[i..i + len].to_vec();
                let at = rng.below(n + 1);
                b.splice(at..at, chunk);
            }
            4 => {
                let t = TOKENS[rng.below(TOKENS.len())].as_bytes();
                let at = rng.below(n + 1);
                b.splice(at..at, t.iter().copied());
            }
            5 => replace_number(rng, &mut b),
            6 if n > 0 => b.truncate(rng.below(n)),
            7 if !other.is_empty() => {
                let cut = rng.below(n + 1);
                let from = rng.below(other.len());
                b.truncate(cut);
                b.extend_from_slice(&other[from..]);
            }
            _ => replace_number(rng, &mut b),
        }
    }
    b
}

/// Replace one run of digits with a hostile number.
fn replace_number(rng: &mut Rng, b: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..b.len())
        .filter(|&i| b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_digit()))
        .collect();
    if starts.is_empty() {
        return;
    }
    let s = starts[rng.below(starts.len())];
    let e = (s..b.len())
        .find(|&i| !b[i].is_ascii_digit())
        .unwrap_or(b.len());
    let t = TOKENS[rng.below(16)].as_bytes();
    b.splice(s..e, t.iter().copied());
}

/// Allocation accounting per thread, for "never allocate more than 10× the input".
pub mod alloc_meter {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    thread_local! {
        static LIVE: Cell<usize> = const { Cell::new(0) };
        static PEAK: Cell<usize> = const { Cell::new(0) };
    }

    /// The system allocator, counting this thread's live and peak bytes.
    pub struct Meter;

    unsafe impl GlobalAlloc for Meter {
        unsafe fn alloc(&self, l: Layout) -> *mut u8 {
            let _ = LIVE.try_with(|c| {
                let v = c.get() + l.size();
                c.set(v);
                let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
            });
            unsafe { System.alloc(l) }
        }
        unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
            let _ = LIVE.try_with(|c| c.set(c.get().saturating_sub(l.size())));
            unsafe { System.dealloc(p, l) }
        }
        unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
            let _ = LIVE.try_with(|c| {
                let v = c.get().saturating_sub(l.size()) + new;
                c.set(v);
                let _ = PEAK.try_with(|pk| pk.set(pk.get().max(v)));
            });
            unsafe { System.realloc(p, l, new) }
        }
    }

    /// Bytes allocated on this thread above the live level when `f` started, at peak.
    pub fn peak_during<R>(f: impl FnOnce() -> R) -> (R, usize) {
        let base = LIVE.with(|c| c.get());
        PEAK.with(|p| p.set(base));
        let r = f();
        let peak = PEAK.with(|p| p.get());
        (r, peak - base)
    }
}

/// Run `parse` on `count` mutants of `seeds`: no panic, no input slower than `max`, and
/// at most `10 × len + slack` bytes allocated; returns (accepted, rejected, slowest).
pub fn fuzz(
    name: &str,
    seeds: &[Vec<u8>],
    count: usize,
    seed: u64,
    slack: usize,
    parse: impl Fn(&[u8]) -> bool,
) -> (usize, usize, std::time::Duration) {
    let mut rng = Rng::new(seed);
    let (mut ok, mut bad) = (0, 0);
    let mut slowest = std::time::Duration::ZERO;
    for k in 0..count {
        let a = &seeds[rng.below(seeds.len())];
        let b = &seeds[rng.below(seeds.len())];
        let input = mutate(&mut rng, a, b);
        let t = std::time::Instant::now();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            alloc_meter::peak_during(|| parse(&input))
        }));
        let dt = t.elapsed();
        slowest = slowest.max(dt);
        let Ok((accepted, bytes)) = result else {
            let path = std::env::temp_dir().join(format!("incise-fuzz-{name}-{k}.bin"));
            let _ = std::fs::write(&path, &input);
            panic!(
                "{name}: input {k} panicked; saved to {} (keep it as a regression input: \
                 tests/fuzz/ in this crate or the app, README there)",
                path.display()
            );
        };
        assert!(
            bytes <= 10 * input.len() + slack,
            "{name}: input {k} ({} bytes) allocated {bytes} bytes",
            input.len()
        );
        assert!(
            dt < std::time::Duration::from_secs(1),
            "{name}: input {k} took {dt:?}"
        );
        if accepted {
            ok += 1;
        } else {
            bad += 1;
        }
    }
    (ok, bad, slowest)
}

/// Inputs per format: `INCISE_FUZZ_INPUTS` or 100,000.
pub fn inputs_per_format() -> usize {
    std::env::var("INCISE_FUZZ_INPUTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000)
}
