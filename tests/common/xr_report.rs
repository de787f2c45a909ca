//! Reading `xr_report.json` in the XR tests (simulated headset and Monado alike).

use serde_json::Value;

/// A field of the report as f64.
pub fn num(r: &Value, key: &str) -> f64 {
    r[key].as_f64().unwrap_or_else(|| panic!("no {key} in {r}"))
}

/// The median tool-to-tissue latency of the report, ms.
pub fn latency_p50(r: &Value) -> f64 {
    r["tool_latency_ms_p50_p95"][0].as_f64().unwrap()
}

/// Issue 19 item 3: a solver slowed by `--slow-sim-ms 250` on its thread steps fewer than
/// 4 frames a second and under 70 % of the full-speed run's, and the tissue shown lags
/// the tool by at least the slow step, more than at full speed.
pub fn assert_slow_sim_steps_less_and_lags(slow: &Value, base: &Value) {
    let (s_base, s_slow) = (num(base, "sim_steps_per_s"), num(slow, "sim_steps_per_s"));
    assert!(
        s_slow < 4.0 && s_slow < 0.7 * s_base,
        "{s_slow} vs {s_base} steps/s"
    );
    assert!(
        latency_p50(slow) >= 250.0 && latency_p50(slow) > latency_p50(base),
        "{slow}\n{base}"
    );
}
