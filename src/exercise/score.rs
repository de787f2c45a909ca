//! The overall score (0–100, documented weights) and the pass/fail checks of an attempt,
//! each with the reason it failed (docs/scoring.md).

use serde::Serialize;

use super::metrics::Metrics;
use super::model::Exercise;

/// Weights of the score's parts (they sum to 100).
pub const WEIGHTS: Weights = Weights {
    completion: 30.0,
    deviation: 20.0,
    depth: 20.0,
    collateral: 15.0,
    force: 10.0,
    time: 5.0,
};

/// Points of each part of the score.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Weights {
    /// Fraction of the plan cut.
    pub completion: f64,
    /// Mean deviation of the trace, against the lateral tolerance.
    pub deviation: f64,
    /// Mean depth error, against the depth tolerance.
    pub depth: f64,
    /// Collateral volume, against the band's volume.
    pub collateral: f64,
    /// Largest force, against the exercise's limit.
    pub force: f64,
    /// Duration, against the time limit.
    pub time: f64,
}

/// One pass condition and how the attempt did on it.
#[derive(Debug, Clone, Serialize)]
pub struct Check {
    /// Which condition (`completion`, `mean_deviation`, …).
    pub name: &'static str,
    /// Whether it holds.
    pub passed: bool,
    /// The measured value and the limit, in words and display units.
    pub detail: String,
}

/// The score and the checks of an attempt.
#[derive(Debug, Clone, Serialize)]
pub struct Verdict {
    /// Overall score, 0..100.
    pub score: f64,
    /// Points earned per part (same keys as [`WEIGHTS`]).
    pub parts: Weights,
    /// Every pass condition.
    pub checks: Vec<Check>,
    /// All conditions hold.
    pub passed: bool,
}

/// Score `m` against `ex`'s tolerances and check its thresholds.
pub fn judge(ex: &Exercise, m: &Metrics) -> Verdict {
    let lat = ex.tolerance.lateral as f64;
    let dtol = ex.tolerance.depth as f64;
    let limit_f = ex.pass.max_force as f64;
    let limit_t = ex.time_limit as f64;
    let unit = |x: f64| x.clamp(0.0, 1.0);
    let parts = Weights {
        completion: WEIGHTS.completion * unit(m.completion),
        deviation: WEIGHTS.deviation * m.mean_deviation.map_or(0.0, |d| unit(1.0 - d / lat)),
        depth: WEIGHTS.depth * m.mean_depth_error.map_or(0.0, |e| unit(1.0 - e / dtol)),
        collateral: WEIGHTS.collateral * unit(1.0 - m.collateral_volume / m.band_volume),
        force: WEIGHTS.force * unit(1.0 - (m.max_force - limit_f).max(0.0) / limit_f),
        time: WEIGHTS.time
            * match m.duration {
                d if d <= limit_t => 1.0,
                d => unit(limit_t / d),
            },
    };
    let score = parts.completion
        + parts.deviation
        + parts.depth
        + parts.collateral
        + parts.force
        + parts.time;
    let p = &ex.pass;
    let mm = |x: f64| format!("{:.1} mm", x * 1e3);
    let mut checks = vec![Check {
        name: "completion",
        passed: m.completion >= p.completion as f64,
        detail: format!(
            "{:.0} % of the plan cut (needs ≥ {:.0} %)",
            m.completion * 100.0,
            p.completion * 100.0
        ),
    }];
    for (name, value, limit, what) in [
        (
            "mean_deviation",
            m.mean_deviation,
            p.mean_deviation,
            "mean deviation from the plan",
        ),
        (
            "max_deviation",
            m.max_deviation,
            p.max_deviation,
            "largest deviation from the plan",
        ),
        (
            "depth_error",
            m.mean_depth_error,
            p.depth_error,
            "mean depth error",
        ),
    ] {
        checks.push(match value {
            Some(v) => Check {
                name,
                passed: v <= limit as f64,
                detail: format!("{what} {} (allowed ≤ {})", mm(v), mm(limit as f64)),
            },
            None => Check {
                name,
                passed: false,
                detail: format!("{what}: nothing was cut along the plan"),
            },
        });
    }
    let deepest = ex.depth as f64 + dtol;
    checks.push(Check {
        name: "max_depth",
        passed: m.max_depth <= deepest,
        detail: format!(
            "deepest cut {} (target {} ± {}, so ≤ {})",
            mm(m.max_depth),
            mm(ex.depth as f64),
            mm(dtol),
            mm(deepest)
        ),
    });
    checks.push(Check {
        name: "collateral",
        passed: m.collateral_volume <= p.collateral as f64,
        detail: format!(
            "{:.1} mm³ of tissue cut outside the tolerance band (allowed ≤ {:.1} mm³)",
            m.collateral_volume * 1e9,
            p.collateral as f64 * 1e9
        ),
    });
    checks.push(Check {
        name: "max_force",
        passed: m.max_force <= limit_f,
        detail: format!(
            "largest blade force {:.2} N (allowed ≤ {:.2} N)",
            m.max_force, limit_f
        ),
    });
    checks.push(Check {
        name: "time",
        passed: m.duration > 0.0 && m.duration <= limit_t,
        detail: match m.duration {
            0.0 => "the blade never touched the tissue".into(),
            d => format!("{d:.2} s from first to last contact (limit {limit_t:.1} s)"),
        },
    });
    checks.push(Check {
        name: "score",
        passed: score >= p.score as f64,
        detail: format!("score {score:.0} / 100 (needs ≥ {:.0})", p.score),
    });
    let passed = checks.iter().all(|c| c.passed);
    Verdict {
        score,
        parts,
        checks,
        passed,
    }
}
