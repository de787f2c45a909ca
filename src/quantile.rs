//! Quantiles of measured times (frame times, latencies), as the benchmarks, the headset's
//! report and the run's closing line state them.

/// The `q` quantile (nearest rank) of `sorted` (ascending); 0 when empty.
pub(crate) fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}
