//! One element on a line: a fixed node and a loaded node of mass m joined by one
//! three-element element, integrated with RK4 over (position, velocity, ratio)
//! (PHYSICS.md §3; the set-up of the closed-form creep-and-recovery test).

use super::element::ElementParams;
use super::error::RheologyError;
use super::rk4::Rk4;
use super::stability::RK4_HALF_DISK_RADIUS;

/// A creep-and-recovery test of one element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreepTest {
    /// The element.
    pub element: ElementParams,
    /// Rest length L0 of the edge, m.
    pub rest_length: f64,
    /// Voigt ratio at rest a0 (natural length `l = a0 L0`).
    pub rest_ratio: f64,
    /// Mass of the loaded node, kg.
    pub node_mass: f64,
    /// Force pulling the loaded node away from the fixed one, N.
    pub force: f64,
    /// Time the force is removed, s.
    pub release: f64,
}

/// One sample of a creep test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreepSample {
    /// Time, s.
    pub time: f64,
    /// Elongation `L − L0`, m.
    pub elongation: f64,
    /// Voigt ratio a.
    pub ratio: f64,
}

impl CreepTest {
    /// The stability limit of this one-node system, s (see `stability.rs`).
    pub fn max_step(&self) -> f64 {
        let m = self.node_mass;
        let rate = (self.element.stiffness / m)
            .sqrt()
            .max(self.element.damping_bound() / m)
            + self.element.ratio_rate_bound();
        RK4_HALF_DISK_RADIUS / rate
    }

    /// Integrate from rest to `end` with step `step`, sampling every `every` steps (and at
    /// the end); the release time is rounded to a whole number of steps.
    pub fn run(
        &self,
        step: f64,
        end: f64,
        every: usize,
    ) -> Result<Vec<CreepSample>, RheologyError> {
        let limit = self.max_step();
        if !(step > 0.0 && step <= limit) {
            return Err(RheologyError::StepTooLarge { step, limit });
        }
        let natural = self.rest_ratio * self.rest_length;
        let p = self.element;
        let (m, l0) = (self.node_mass, self.rest_length);
        let mut y = [l0, 0.0, self.rest_ratio];
        let mut rk = Rk4::new(3);
        let steps = (end / step).round() as usize;
        let release_step = (self.release / step).round() as usize;
        let every = every.max(1);
        let sample = |n: usize, y: &[f64; 3]| CreepSample {
            time: n as f64 * step,
            elongation: y[0] - l0,
            ratio: y[2],
        };
        let mut out = vec![sample(0, &y)];
        for n in 0..steps {
            let force = if n < release_step { self.force } else { 0.0 };
            rk.step(&mut y, n as f64 * step, step, |_, s, d| {
                let r = p.respond(natural, s[0], s[1], s[2]);
                d[0] = s[1];
                d[1] = (force - r.tension) / m;
                d[2] = r.ratio_rate;
            });
            // PHYSICS.md §3, eqs. (4), (5): clamp after each step.
            y[2] = y[2].clamp(p.ratio_min, p.ratio_max);
            if !y.iter().all(|v| v.is_finite()) {
                return Err(RheologyError::Diverged {
                    time: (n + 1) as f64 * step,
                });
            }
            if (n + 1) % every == 0 || n + 1 == steps {
                out.push(sample(n + 1, &y));
            }
        }
        Ok(out)
    }
}
