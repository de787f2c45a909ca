//! Classical fourth-order Runge–Kutta over a flat state vector (PHYSICS.md §3:
//! positions, velocities and Voigt ratios are integrated together).

/// Scratch buffers for RK4 steps of a state of fixed length.
#[derive(Debug, Clone)]
pub struct Rk4 {
    sum: Vec<f64>,
    stage: Vec<f64>,
    rate: Vec<f64>,
}

impl Rk4 {
    /// Buffers for a state of `len` numbers.
    pub fn new(len: usize) -> Self {
        Rk4 {
            sum: vec![0.0; len],
            stage: vec![0.0; len],
            rate: vec![0.0; len],
        }
    }

    /// Advance `y` from time `t` by `h` for `dy/dt = f(t, y)`; `f(t, y, dy)` writes the rate.
    ///
    /// `y += h/6 (k1 + 2k2 + 2k3 + k4)` with `k1 = f(t, y)`, `k2 = f(t + h/2, y + h/2 k1)`,
    /// `k3 = f(t + h/2, y + h/2 k2)`, `k4 = f(t + h, y + h k3)`.
    pub fn step(
        &mut self,
        y: &mut [f64],
        t: f64,
        h: f64,
        mut f: impl FnMut(f64, &[f64], &mut [f64]),
    ) {
        assert_eq!(y.len(), self.sum.len(), "RK4 state length changed");
        let Rk4 { sum, stage, rate } = self;
        f(t, y, rate);
        for i in 0..y.len() {
            sum[i] = rate[i];
            stage[i] = y[i] + 0.5 * h * rate[i];
        }
        f(t + 0.5 * h, stage, rate);
        for i in 0..y.len() {
            sum[i] += 2.0 * rate[i];
            stage[i] = y[i] + 0.5 * h * rate[i];
        }
        f(t + 0.5 * h, stage, rate);
        for i in 0..y.len() {
            sum[i] += 2.0 * rate[i];
            stage[i] = y[i] + h * rate[i];
        }
        f(t + h, stage, rate);
        for i in 0..y.len() {
            y[i] += h / 6.0 * (sum[i] + rate[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_decay_error_shrinks_sixteenfold() {
        let err = |n: usize| {
            let mut rk = Rk4::new(2);
            let mut y = [1.0, 0.0];
            let h = 1.0 / n as f64;
            for i in 0..n {
                // y0' = −y0 (decay), y1' = y0 (its integral).
                rk.step(&mut y, i as f64 * h, h, |_, y, d| {
                    d[0] = -y[0];
                    d[1] = y[0];
                });
            }
            (y[0] - (-1.0f64).exp()).abs()
        };
        let ratio = err(20) / err(40);
        assert!((ratio - 16.0).abs() < 1.0, "{ratio}");
    }
}
