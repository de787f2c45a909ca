//! This machine's nominal single-precision peak, for the GFLOP/s columns of `incise bench
//! realtime` (issue 35): threads × clock × flops per cycle of the widest fused
//! multiply-add the CPU reports. An estimate, named as such in docs/performance.md: the
//! clock is `cpu MHz` of /proc/cpuinfo (the current clock, not a boost), and two FMA pipes
//! per core are assumed (Haswell and later, Zen 2 and later).

use serde::Serialize;

/// The peak and how it was estimated.
#[derive(Debug, Clone, Serialize)]
pub struct Peak {
    /// GFLOP/s for the threads asked.
    pub gflops: f64,
    /// The estimate in words: "2 × 2.45 GHz × 32 flop/cycle (AVX2+FMA)".
    pub how: String,
}

/// Single-precision flops per cycle per core of the widest vector FMA in `flags`
/// (two pipes: lanes × 2 flops × 2), and its name.
pub fn flops_per_cycle(flags: &str) -> (f64, &'static str) {
    let has = |f: &str| flags.split_whitespace().any(|x| x == f);
    if has("avx512f") {
        (64.0, "AVX-512+FMA")
    } else if has("avx2") && has("fma") {
        (32.0, "AVX2+FMA")
    } else if has("avx") {
        (16.0, "AVX")
    } else {
        (8.0, "SSE")
    }
}

/// The peak of `threads` cores of this machine, or `None` where /proc/cpuinfo does not
/// say (not Linux, or no clock).
pub fn peak(threads: usize) -> Option<Peak> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    let field = |name: &str| {
        info.lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
    };
    let mhz: f64 = field("cpu MHz")?.parse().ok()?;
    let (per_cycle, isa) = flops_per_cycle(&field("flags").unwrap_or_default());
    Some(Peak {
        gflops: threads as f64 * mhz * 1e-3 * per_cycle,
        how: format!(
            "{threads} × {:.2} GHz × {per_cycle} flop/cycle ({isa})",
            mhz * 1e-3
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The widest unit wins, and AVX2 without FMA is not counted as FMA.
    #[test]
    fn the_widest_fma_sets_the_flops_per_cycle() {
        assert_eq!(flops_per_cycle("sse2 avx avx2 fma avx512f").0, 64.0);
        assert_eq!(flops_per_cycle("sse2 avx fma avx2").0, 32.0);
        assert_eq!(flops_per_cycle("sse2 avx avx2").0, 16.0);
        assert_eq!(flops_per_cycle("sse2").0, 8.0);
    }
}
