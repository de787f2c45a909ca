//! Scripted grab: a set of nodes moved kinematically along a path at a given speed.

use glam::Vec3;

/// Nodes held by a virtual forceps and moved along a polyline of displacements.
#[derive(Debug, Clone, PartialEq)]
pub struct Grab {
    /// Grabbed nodes.
    pub nodes: Vec<u32>,
    /// Waypoints of the displacement from the grab's start positions (metres); the path
    /// starts at zero displacement and visits them in order.
    pub waypoints: Vec<Vec3>,
    /// Speed along the path, m/s.
    pub speed: f32,
    /// Simulation time at which the pull starts, s.
    pub start_time: f32,
}

impl Grab {
    /// Displacement at simulation time `t`: arclength `speed·(t − start)` along the path,
    /// held at the last waypoint once reached.
    pub fn offset_at(&self, t: f64) -> Vec3 {
        let mut remaining = (self.speed as f64 * (t - self.start_time as f64)).max(0.0) as f32;
        let mut from = Vec3::ZERO;
        for &to in &self.waypoints {
            let len = (to - from).length();
            if remaining <= len {
                return if len > 0.0 {
                    from + (to - from) * (remaining / len)
                } else {
                    from
                };
            }
            remaining -= len;
            from = to;
        }
        from
    }

    /// Total path length, m.
    pub fn path_length(&self) -> f32 {
        let mut from = Vec3::ZERO;
        let mut len = 0.0;
        for &to in &self.waypoints {
            len += (to - from).length();
            from = to;
        }
        len
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_follows_the_polyline_and_holds_at_the_end() {
        let g = Grab {
            nodes: vec![0],
            waypoints: vec![Vec3::X, Vec3::new(1.0, 1.0, 0.0)],
            speed: 0.5,
            start_time: 1.0,
        };
        assert_eq!(g.offset_at(0.5), Vec3::ZERO);
        assert!((g.offset_at(2.0) - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
        // t = 4: arclength 1.5, half-way along the second segment.
        assert!((g.offset_at(4.0) - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-6);
        assert!((g.offset_at(5.0) - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        assert!((g.offset_at(100.0) - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        assert_eq!(g.path_length(), 2.0);
    }
}
