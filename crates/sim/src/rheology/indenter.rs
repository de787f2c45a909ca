//! A rigid flat indenter that presses a body's top face down, holds and lifts off: a
//! unilateral contact applied after every RK4 step (the seed's press-and-release, Figs. 3–6).

use glam::DVec3;

/// Indentation depth over time: a linear press to `depth`, a hold, a linear lift-off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressSchedule {
    /// Depth of the indenter face below the rest top at full press, m.
    pub depth: f64,
    /// Duration of the press ramp, s.
    pub press: f64,
    /// Duration of the hold at full depth, s.
    pub hold: f64,
    /// Duration of the lift-off ramp back to the rest top, s.
    pub lift: f64,
}

impl PressSchedule {
    /// Time the indenter leaves the rest top for good, s.
    pub fn end(&self) -> f64 {
        self.press + self.hold + self.lift
    }

    /// Indenter depth below the rest top at time `t` and its rate (m, m/s).
    pub fn depth_at(&self, t: f64) -> (f64, f64) {
        if t < self.press {
            (self.depth * t / self.press, self.depth / self.press)
        } else if t < self.press + self.hold {
            (self.depth, 0.0)
        } else if t < self.end() {
            let left = self.end() - t;
            (self.depth * left / self.lift, -self.depth / self.lift)
        } else {
            (0.0, 0.0)
        }
    }
}

/// A flat rectangular indenter face over a body's top.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatIndenter {
    /// Centre of the face in x, y, m.
    pub centre: [f64; 2],
    /// Half extents of the face in x, y, m.
    pub half_size: [f64; 2],
    /// Height of the undeformed top face, m.
    pub rest_top: f64,
    /// Depth over time.
    pub schedule: PressSchedule,
    /// Nodes that can touch the face (the top-surface nodes).
    pub candidates: Vec<u32>,
}

impl FlatIndenter {
    /// Keep every candidate node under the face at or below it at time `t`: a node above
    /// the face is put on it and its upward velocity limited to the face's (inelastic
    /// contact). Positions and velocities are `x[3i..3i+3]`, `v[3i..3i+3]`.
    pub fn apply(&self, t: f64, x: &mut [f64], v: &mut [f64]) {
        if t >= self.schedule.end() {
            return;
        }
        let (depth, rate) = self.schedule.depth_at(t);
        let (face, face_velocity) = (self.rest_top - depth, -rate);
        for &n in &self.candidates {
            let i = 3 * n as usize;
            let p = DVec3::from_slice(&x[i..i + 3]);
            let under = (p.x - self.centre[0]).abs() <= self.half_size[0]
                && (p.y - self.centre[1]).abs() <= self.half_size[1];
            if under && p.z > face {
                x[i + 2] = face;
                v[i + 2] = v[i + 2].min(face_velocity);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_ramps_holds_and_lifts() {
        let s = PressSchedule {
            depth: 0.01,
            press: 1.0,
            hold: 2.0,
            lift: 0.5,
        };
        assert_eq!(s.depth_at(0.5), (0.005, 0.01));
        assert_eq!(s.depth_at(2.0), (0.01, 0.0));
        assert!((s.depth_at(3.25).0 - 0.005).abs() < 1e-12);
        assert_eq!(s.depth_at(4.0), (0.0, 0.0));
    }

    #[test]
    fn contact_pushes_only_nodes_under_the_face_and_above_it() {
        let ind = FlatIndenter {
            centre: [0.0, 0.0],
            half_size: [0.01, 0.01],
            rest_top: 0.02,
            schedule: PressSchedule {
                depth: 0.004,
                press: 1.0,
                hold: 1.0,
                lift: 1.0,
            },
            candidates: vec![0, 1, 2],
        };
        // Node 0 under the face and above it, node 1 beside it, node 2 already below.
        let mut x = [0.0, 0.0, 0.02, 0.05, 0.0, 0.02, 0.0, 0.005, 0.01];
        let mut v = [0.0; 9];
        ind.apply(1.5, &mut x, &mut v);
        assert_eq!(x[2], 0.016);
        assert_eq!(v[2], 0.0);
        assert_eq!(x[5], 0.02);
        assert_eq!(x[8], 0.01);
    }
}
