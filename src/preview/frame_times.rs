//! The last seconds of frame timings (simulation, rendering, whole frame) for the
//! panel's graph.

use std::collections::VecDeque;

/// Frames kept for the graph.
const KEPT: usize = 240;

/// One frame's timings, ms.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameTime {
    /// Simulation step (0 while paused).
    pub sim_ms: f64,
    /// Recording and submitting the 3D view and the panel.
    pub render_ms: f64,
    /// Time since the previous frame.
    pub frame_ms: f64,
}

/// A ring of recent frame timings.
#[derive(Debug, Default)]
pub struct FrameTimes {
    frames: VecDeque<FrameTime>,
}

impl FrameTimes {
    /// Add a frame, dropping the oldest beyond the kept window.
    pub fn push(&mut self, t: FrameTime) {
        if self.frames.len() == KEPT {
            self.frames.pop_front();
        }
        self.frames.push_back(t);
    }

    /// The kept frames, oldest first.
    pub fn frames(&self) -> impl Iterator<Item = &FrameTime> {
        self.frames.iter()
    }

    /// Mean of the last (up to) 30 frames.
    pub fn recent_mean(&self) -> FrameTime {
        let n = self.frames.len().min(30);
        if n == 0 {
            return FrameTime::default();
        }
        let sum = self
            .frames
            .iter()
            .rev()
            .take(n)
            .fold(FrameTime::default(), |a, f| FrameTime {
                sim_ms: a.sim_ms + f.sim_ms,
                render_ms: a.render_ms + f.render_ms,
                frame_ms: a.frame_ms + f.frame_ms,
            });
        let k = n as f64;
        FrameTime {
            sim_ms: sum.sim_ms / k,
            render_ms: sum.render_ms / k,
            frame_ms: sum.frame_ms / k,
        }
    }

    /// Frames per second over the recent mean frame time.
    pub fn fps(&self) -> f64 {
        let ms = self.recent_mean().frame_ms;
        if ms > 0.0 { 1e3 / ms } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_a_window_and_averages_the_recent_frames() {
        let mut t = FrameTimes::default();
        assert_eq!(t.fps(), 0.0);
        for i in 0..300 {
            t.push(FrameTime {
                sim_ms: i as f64,
                render_ms: 2.0,
                frame_ms: 20.0,
            });
        }
        assert_eq!(t.frames().count(), KEPT);
        assert_eq!(t.frames().next().unwrap().sim_ms, 60.0);
        let m = t.recent_mean();
        assert!((m.sim_ms - (270..300).sum::<i32>() as f64 / 30.0).abs() < 1e-9);
        assert!((t.fps() - 50.0).abs() < 1e-9);
    }
}
