//! The refresh-rate manager of PHYSICS.md §2.5 (Nakao 2003 §4.2): each loop, adjust the
//! number of free nodes so that the force computation fits a fixed time budget.

/// Keeps the loop time at a budget by scaling the free-node count.
///
/// The cost of a loop is close to proportional to its free nodes, so after a loop that took
/// `t` with `n` nodes, `n · budget / t` nodes would have fit; the manager moves part of the
/// way there (`gain`), limits the change per loop, and clamps to `[min_nodes, max_nodes]`.
#[derive(Debug, Clone, PartialEq)]
pub struct RefreshRateManager {
    budget_ms: f64,
    free: f64,
    min_nodes: usize,
    max_nodes: usize,
    gain: f64,
}

impl RefreshRateManager {
    /// The paper's budget: 5.6 ms per loop.
    pub const PAPER_BUDGET_MS: f64 = 5.6;

    /// A manager for `budget_ms` per loop, starting at `initial` free nodes, never below
    /// `min_nodes` nor above `max_nodes`.
    pub fn new(budget_ms: f64, initial: usize, min_nodes: usize, max_nodes: usize) -> Self {
        let min_nodes = min_nodes.max(1);
        let max_nodes = max_nodes.max(min_nodes);
        RefreshRateManager {
            budget_ms: budget_ms.max(1e-6),
            free: initial.clamp(min_nodes, max_nodes) as f64,
            min_nodes,
            max_nodes,
            gain: 0.5,
        }
    }

    /// The time budget per loop, ms.
    pub fn budget_ms(&self) -> f64 {
        self.budget_ms
    }

    /// Free nodes for the next loop.
    pub fn free_nodes(&self) -> usize {
        self.free.round() as usize
    }

    /// Report that the last loop took `measured_ms` with [`Self::free_nodes`] free nodes;
    /// returns the free-node count for the next loop.
    pub fn update(&mut self, measured_ms: f64) -> usize {
        if measured_ms.is_finite() && measured_ms > 0.0 {
            let target = self.free * self.budget_ms / measured_ms;
            // At most double or halve per loop: one slow loop (an interrupt) must not
            // collapse the free set.
            let target = target.clamp(0.5 * self.free, 2.0 * self.free);
            self.free += self.gain * (target - self.free);
        }
        self.free = self
            .free
            .clamp(self.min_nodes as f64, self.max_nodes as f64);
        self.free_nodes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A loop whose cost is `overhead + per_node · n` ms, with a deterministic ±10 % jitter
    /// and an occasional 4× spike (an OS interrupt).
    fn plant(n: usize, k: usize) -> f64 {
        let jitter = 1.0 + 0.1 * ((k as f64 * 2.399).sin());
        let spike = if k % 37 == 0 { 4.0 } else { 1.0 };
        (0.3 + 0.012 * n as f64) * jitter * spike
    }

    #[test]
    fn loop_time_settles_within_15_percent_of_the_budget() {
        let mut m = RefreshRateManager::new(RefreshRateManager::PAPER_BUDGET_MS, 50, 10, 100_000);
        let mut times = Vec::new();
        for k in 1..400 {
            let t = plant(m.free_nodes(), k);
            times.push((k, t));
            m.update(t);
        }
        // After 20 loops, every loop except a spike and the three loops of recovery after it
        // is within ±15 % of the budget.
        for &(k, t) in times.iter().filter(|(k, _)| *k > 20 && k % 37 > 3) {
            let rel = (t - 5.6).abs() / 5.6;
            assert!(rel <= 0.15, "loop {k}: {t:.3} ms");
        }
        // The paper's figure: about (5.6 − 0.3)/0.012 ≈ 440 nodes fit.
        assert!(
            (m.free_nodes() as f64 - 441.0).abs() < 60.0,
            "{}",
            m.free_nodes()
        );
    }

    #[test]
    fn count_is_clamped_and_ignores_bad_measurements() {
        let mut m = RefreshRateManager::new(1.0, 100, 20, 150);
        assert_eq!(m.update(f64::NAN), 100);
        for _ in 0..50 {
            m.update(0.001);
        }
        assert_eq!(m.free_nodes(), 150);
        for _ in 0..50 {
            m.update(1000.0);
        }
        assert_eq!(m.free_nodes(), 20);
    }
}
