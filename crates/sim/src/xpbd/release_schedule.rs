//! When the release check runs: on a fixed simulation-time interval, so that tearing does
//! not depend on the frame rate (docs/physics-notes.md, "Release schedule"). The seed
//! checks once per frame (`None`).

/// Tolerance on interval boundaries, in intervals: a boundary that falls on a substep's end
/// up to rounding (f32 frame times summed over minutes) counts for that substep.
const BOUNDARY_TOLERANCE: f64 = 1e-3;

/// The interval in f64: `1/N s` given in f32 is taken as exactly `1/N`.
fn exact_interval(dt: f32) -> f64 {
    let rate = 1.0 / dt as f64;
    if (rate - rate.round()).abs() < 1e-4 * rate {
        1.0 / rate.round()
    } else {
        dt as f64
    }
}

/// Indices of the substeps (0-based, of `n` substeps of length `h` starting at `time`)
/// after which a release check runs: those in which a multiple of `interval` falls,
/// `(t_{s−1}, t_s]`; with `None`, the last substep only.
pub fn release_checks(time: f64, h: f32, n: u32, interval: Option<f32>) -> Vec<u32> {
    let Some(dt) = interval else {
        return vec![n.saturating_sub(1)];
    };
    let dt = exact_interval(dt);
    let tick = |t: f64| (t / dt + BOUNDARY_TOLERANCE).floor();
    let mut before = tick(time);
    let mut out = Vec::new();
    for s in 0..n {
        let now = tick(time + (s + 1) as f64 * h as f64);
        if now > before {
            out.push(s);
        }
        before = now;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn once_per_frame_without_an_interval() {
        assert_eq!(release_checks(0.3, 1e-3, 10, None), vec![9]);
    }

    /// The same substep length at 30, 60 and 240 Hz: checks every 10 substeps of 1/2400 s
    /// wherever the frame boundaries fall.
    #[test]
    fn interval_checks_do_not_depend_on_the_frame_rate() {
        let h = 1.0 / 2400.0;
        for (hz, n) in [(30.0, 80u32), (60.0, 40), (240.0, 10)] {
            let mut all = Vec::new();
            for frame in 0..(hz as u32) {
                let time = frame as f64 / hz;
                all.extend(
                    release_checks(time, h, n, Some(1.0 / 240.0))
                        .into_iter()
                        .map(|s| frame * n + s),
                );
            }
            let expect: Vec<u32> = (0..240).map(|k| k * 10 + 9).collect();
            assert_eq!(all, expect, "{hz} Hz");
        }
    }

    /// An interval that is not a whole number of substeps: one check per interval, at
    /// the substep in which it ends.
    #[test]
    fn uneven_intervals_check_once_each() {
        let (h, n) = (1.0 / 1080.0f32, 15); // 72 Hz, 15 substeps: 4.5 substeps a check
        let mut count = 0;
        for frame in 0..72 {
            count += release_checks(frame as f64 / 72.0, h, n, Some(1.0 / 240.0)).len();
        }
        assert_eq!(count, 240);
    }
}
