//! Frame pacing: the simulation advances on its own fixed frame dt, decoupled from the
//! display rate (72/90/120 Hz), inside a time budget per display frame. When a display
//! frame runs late, substeps are reduced first (down to the stable minimum); only when
//! even those do not fit is simulated time given up (the tissue runs slower than real
//! time) — the display never waits for the simulation.

/// What the pacer needs to know of the simulation and the display.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PacingConfig {
    /// Simulation frame length, s (the scene's `frame_dt`).
    pub sim_dt: f64,
    /// The scene's substeps per simulation frame.
    pub nominal_substeps: u32,
    /// The fewest substeps that stay stable for the material and mesh.
    pub min_substeps: u32,
    /// Fraction of a display period the simulation may use (the rest renders).
    pub budget_fraction: f64,
    /// Most simulation frames per display frame (catching up after a stall).
    pub max_sim_frames: u32,
}

/// The work for one display frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FramePlan {
    /// Simulation frames to step now.
    pub sim_frames: u32,
    /// Substeps per simulation frame.
    pub substeps: u32,
}

/// The pacer: accumulates display time and plans simulation frames against the measured
/// cost of a substep.
#[derive(Debug, Clone)]
pub struct FramePacer {
    cfg: PacingConfig,
    accumulator: f64,
    substeps: u32,
    last_display_time: Option<f64>,
    /// Smoothed wall time of one substep, s (None until measured).
    substep_cost: Option<f64>,
    dropped: f64,
}

impl FramePacer {
    /// A pacer starting at the nominal substeps.
    pub fn new(cfg: PacingConfig) -> Self {
        let min = cfg.min_substeps.clamp(1, cfg.nominal_substeps.max(1));
        FramePacer {
            cfg: PacingConfig {
                min_substeps: min,
                nominal_substeps: cfg.nominal_substeps.max(min),
                max_sim_frames: cfg.max_sim_frames.max(1),
                ..cfg
            },
            accumulator: 0.0,
            substeps: cfg.nominal_substeps.max(min),
            last_display_time: None,
            substep_cost: None,
            dropped: 0.0,
        }
    }

    /// The configuration in use (limits applied).
    pub fn config(&self) -> &PacingConfig {
        &self.cfg
    }

    /// Simulated time given up so far, s.
    pub fn dropped_time(&self) -> f64 {
        self.dropped
    }

    /// Time until the next simulation frame is owed, s (0 when one is owed now): how
    /// long a simulation thread paced to real time may sleep.
    pub fn until_next_frame(&self) -> f64 {
        (self.cfg.sim_dt - self.accumulator).max(0.0)
    }

    /// Report the wall time `sim_wall_s` the last plan's `plan.sim_frames × plan.substeps`
    /// substeps took (exponentially smoothed, so one hiccup does not halve the substeps).
    pub fn record(&mut self, plan: FramePlan, sim_wall_s: f64) {
        let n = plan.sim_frames as f64 * plan.substeps as f64;
        if n <= 0.0 || !sim_wall_s.is_finite() || sim_wall_s < 0.0 {
            return;
        }
        let c = sim_wall_s / n;
        self.substep_cost = Some(match self.substep_cost {
            None => c,
            Some(old) => 0.5 * old + 0.5 * c,
        });
    }

    /// The plan for the display frame shown at `display_time` (s, the runtime's predicted
    /// display time), `display_period` s after the previous one.
    pub fn plan(&mut self, display_time: f64, display_period: f64) -> FramePlan {
        self.advance_to(display_time, display_period);
        let owed = self.owed();
        self.take(owed, display_period)
    }

    /// The simulation thread's plan at `now` (s on its clock), the display's newest pose
    /// `fresh` when no frame has been stepped with it yet. The thread steps a frame as
    /// soon as a new pose arrives instead of on its own clock, so the tissue answers the
    /// pose a display period sooner: with a fresh pose a frame due within one frame is
    /// stepped now (simulated time then leads real time by at most a frame), and with a
    /// pose already stepped with, one owed frame waits up to a frame longer for the next
    /// (a display slower than the simulation leaves it a frame behind, stepping on its own
    /// clock). Over time the frames are the scene's rate either way.
    pub fn plan_on_thread(&mut self, now: f64, fresh: bool) -> FramePlan {
        let dt = self.cfg.sim_dt;
        self.advance_to(now, dt);
        let owed = self.owed();
        let frames = match fresh {
            true if self.accumulator >= -1e-9 => owed.max(1),
            true => owed,
            false => owed.saturating_sub(1),
        };
        self.take(frames, dt)
    }

    /// How long the simulation thread may wait for the display's next pose before
    /// [`FramePacer::plan_on_thread`] plans a frame with the pose it has, s (0: now). A
    /// fresh pose that came while the simulation was a frame ahead waits for the next one
    /// (which will find it due) rather than start a frame late into the display's period.
    pub fn until_due_on_thread(&self, fresh: bool) -> f64 {
        let due = if fresh { 1.0 } else { 2.0 };
        (due * self.cfg.sim_dt - self.accumulator).max(0.0)
    }

    /// Add the display time elapsed since the last plan.
    fn advance_to(&mut self, display_time: f64, display_period: f64) {
        let elapsed = match self.last_display_time {
            Some(t) if display_time > t => display_time - t,
            Some(_) => 0.0,
            None => display_period,
        };
        self.last_display_time = Some(display_time);
        self.accumulator += elapsed;
    }

    /// Whole frames owed.
    fn owed(&self) -> u32 {
        ((self.accumulator + 1e-9) / self.cfg.sim_dt)
            .floor()
            .max(0.0) as u32
    }

    /// Step `frames` (at most the catch-up limit, the rest given up) at the substeps that
    /// fit `display_period`'s budget; fewer frames, their time given up, where even the
    /// fewest substeps do not fit.
    fn take(&mut self, mut frames: u32, display_period: f64) -> FramePlan {
        let dt = self.cfg.sim_dt;
        if frames > self.cfg.max_sim_frames {
            let extra = (frames - self.cfg.max_sim_frames) as f64 * dt;
            self.dropped += extra;
            self.accumulator -= extra;
            frames = self.cfg.max_sim_frames;
        }
        let budget = self.cfg.budget_fraction * display_period;
        let substeps = match self.substep_cost {
            Some(c) if frames > 0 && c > 0.0 => {
                let affordable = (budget / (c * frames as f64)).floor() as u32;
                // Recover gently (a quarter more per frame), cut at once.
                let grown = self.substeps + (self.substeps / 4).max(1);
                affordable.min(grown).min(self.cfg.nominal_substeps)
            }
            _ => self.substeps,
        }
        .max(self.cfg.min_substeps);
        // Even the fewest substeps do not fit: simulate fewer frames, give up that time.
        if let Some(c) = self.substep_cost {
            while frames > 1 && c * (frames * substeps) as f64 > budget {
                frames -= 1;
                self.dropped += dt;
                self.accumulator -= dt;
            }
        }
        self.accumulator -= frames as f64 * dt;
        self.substeps = substeps;
        FramePlan {
            sim_frames: frames,
            substeps,
        }
    }
}

/// How long a simulation thread about to step with a pose `age` s old should wait for the
/// display's next pose instead, s (`None`: start now): only where a step of `step` s shows
/// at the same display frame either way, as display frames of `period` s take the newest
/// state when their pose arrives. Started now, the step ends `age + step` after its pose
/// arrived and shows at the first display frame after that; started on the next pose, at
/// `period + step`; the two are the same frame when `age` exceeds `⌈step/period⌉·period −
/// step` (with [`ALIGN_MARGIN`] for the step's estimate). The frame is then shown from a
/// pose up to a period newer, at the cost of the wait, which the thread does not step in.
pub fn wait_for_next_pose(age: f64, step: f64, period: f64) -> Option<f64> {
    if !(period > 0.0 && step > 0.0) || age >= period {
        return None;
    }
    let slack = (step / period).ceil() * period - step;
    (age > slack + ALIGN_MARGIN).then_some(period - age + ALIGN_MARGIN)
}

/// What [`wait_for_next_pose`] allows for a step's time differing from its estimate, s.
pub const ALIGN_MARGIN: f64 = 0.001;

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> PacingConfig {
        PacingConfig {
            sim_dt: 1.0 / 60.0,
            nominal_substeps: 20,
            min_substeps: 8,
            budget_fraction: 0.5,
            max_sim_frames: 3,
        }
    }

    #[test]
    fn the_simulation_keeps_its_own_rate_under_a_faster_display() {
        // 72 Hz display, 60 Hz simulation: over one second, 60 simulation frames in 72
        // display frames, some display frames with none.
        let mut p = FramePacer::new(cfg());
        let period = 1.0 / 72.0;
        let plans: Vec<FramePlan> = (1..=72)
            .map(|i| p.plan(i as f64 * period, period))
            .collect();
        let total: u32 = plans.iter().map(|p| p.sim_frames).sum();
        assert!((59..=60).contains(&total), "{total}");
        assert_eq!(
            plans.iter().filter(|p| p.sim_frames == 0).count() as u32,
            72 - total
        );
        assert!(plans.iter().all(|p| p.substeps == 20));
        assert_eq!(p.dropped_time(), 0.0);
    }

    #[test]
    fn a_late_frame_reduces_substeps_before_giving_up_time() {
        let mut p = FramePacer::new(cfg());
        let period = 1.0 / 60.0;
        let first = p.plan(period, period);
        assert_eq!(
            first,
            FramePlan {
                sim_frames: 1,
                substeps: 20
            }
        );
        // Budget 8.33 ms; 20 substeps took 16 ms: 0.8 ms each → 10 substeps fit.
        p.record(first, 20.0 * 0.0008);
        let second = p.plan(2.0 * period, period);
        assert_eq!(
            second,
            FramePlan {
                sim_frames: 1,
                substeps: 10
            }
        );
        assert_eq!(p.dropped_time(), 0.0);
        // Much slower (2 ms a substep, smoothed to 1.4 ms): 5 would fit, the floor is 8 —
        // one simulation frame is still stepped (never zero while time is owed).
        p.record(second, 10.0 * 0.002);
        let third = p.plan(3.0 * period, period);
        assert_eq!(
            third,
            FramePlan {
                sim_frames: 1,
                substeps: 8
            }
        );
        // A display stall of 4 periods: at most 3 frames are owed, the rest is given up,
        // and of those only as many as fit at 8 substeps are stepped.
        p.record(third, 8.0 * 0.0001);
        let stalled = p.plan(7.0 * period, period);
        assert!(stalled.sim_frames <= 3 && stalled.sim_frames >= 1);
        assert!(p.dropped_time() >= period - 1e-9, "{}", p.dropped_time());
    }

    #[test]
    fn substeps_recover_gradually_once_frames_are_cheap_again() {
        let mut p = FramePacer::new(cfg());
        let period = 1.0 / 60.0;
        let plan = p.plan(period, period);
        p.record(plan, 20.0 * 0.002); // very late: down to the floor
        let low = p.plan(2.0 * period, period);
        assert_eq!(low.substeps, 8);
        let mut t = 2.0;
        let mut last = low;
        let mut seen = vec![low.substeps];
        for _ in 0..20 {
            p.record(last, last.substeps as f64 * 1e-6);
            t += 1.0;
            last = p.plan(t * period, period);
            seen.push(last.substeps);
        }
        // Back to nominal, never above it, at most a quarter more per frame.
        assert_eq!(*seen.last().unwrap(), 20, "{seen:?}");
        for w in seen.windows(2) {
            assert!(w[1] >= w[0] && w[1] - w[0] <= (w[0] / 4).max(1), "{seen:?}");
        }
    }

    #[test]
    fn until_next_frame_is_what_is_left_of_the_frame_not_yet_owed() {
        let mut p = FramePacer::new(cfg());
        let dt = 1.0 / 60.0;
        // A quarter of a frame elapsed: none owed, three quarters to wait.
        let plan = p.plan(0.25 * dt, 0.25 * dt);
        assert_eq!(plan.sim_frames, 0);
        assert!((p.until_next_frame() - 0.75 * dt).abs() < 1e-12);
        // A frame and a half: one owed and stepped, half a frame to wait.
        let plan = p.plan(1.5 * dt, 0.25 * dt);
        assert_eq!(plan.sim_frames, 1);
        assert!((p.until_next_frame() - 0.5 * dt).abs() < 1e-9);
    }

    /// The simulation thread of a 60 Hz scene beside a 72 Hz display, its frames taking
    /// `step` s: it plans when a pose arrives (each display period) and again when a
    /// frame ends or its wait runs out. Returns, per frame stepped, the display frame
    /// whose pose it started on and how long after that pose's arrival it started.
    fn thread_beside_display(step: f64, display_hz: f64) -> Vec<(u64, f64)> {
        let mut p = FramePacer::new(cfg());
        let period = 1.0 / display_hz;
        let (mut now, mut stepped, mut started) = (0.0f64, None, Vec::new());
        while now < 1.0 {
            let newest = (now / period + 1e-9).floor() as u64;
            let fresh = stepped != Some(newest);
            let plan = p.plan_on_thread(now, fresh);
            if plan.sim_frames > 0 {
                for _ in 0..plan.sim_frames {
                    started.push((newest, now - newest as f64 * period));
                }
                stepped = Some(newest);
                now += step * plan.sim_frames as f64;
            } else {
                // Woken by the next pose or when a frame falls due, whichever is first.
                let next_pose = (newest + 1) as f64 * period;
                now = next_pose.min(now + p.until_due_on_thread(fresh).max(1e-6));
            }
        }
        started
    }

    #[test]
    fn on_its_thread_a_fast_simulation_steps_as_each_pose_arrives() {
        // 6 ms frames: 60 frames in the second, every one started the moment a display
        // frame's pose arrived (so the tissue answers it by the next display frame), and
        // never two on one pose: the display's 72 poses give 60 frames, the scene's rate.
        let started = thread_beside_display(0.006, 72.0);
        assert!((59..=61).contains(&started.len()), "{}", started.len());
        assert!(
            started.iter().all(|&(_, late)| late < 1e-6),
            "a frame waited for its own clock: {started:?}"
        );
        let mut poses: Vec<u64> = started.iter().map(|s| s.0).collect();
        poses.dedup();
        assert_eq!(poses.len(), started.len(), "two frames on one pose");
    }

    #[test]
    fn on_its_thread_a_slower_display_leaves_the_simulation_its_own_rate() {
        // A 20 Hz display (Monado's null compositor): the frames between its poses are
        // stepped on the thread's own clock, a frame behind it, and the second still
        // holds the scene's 60 frames.
        let started = thread_beside_display(0.002, 20.0);
        assert!((58..=61).contains(&started.len()), "{}", started.len());
        // Each pose stepped with at once (the frame it finds owed, a frame late, and the
        // one due: two of the three a pose spans), the third between poses, not caught up
        // on the next pose.
        let on_pose = started.iter().filter(|&&(_, late)| late < 1e-6).count();
        assert!(
            (20..=42).contains(&on_pose),
            "{on_pose} frames started on a pose"
        );
    }

    #[test]
    fn on_its_thread_a_pose_already_stepped_with_waits_a_frame_for_the_next() {
        let mut p = FramePacer::new(cfg());
        let dt = 1.0 / 60.0;
        assert_eq!(p.plan_on_thread(0.0, true).sim_frames, 1, "the first frame");
        // Half a frame later with the same pose: nothing due yet.
        assert_eq!(p.plan_on_thread(0.5 * dt, false).sim_frames, 0);
        // A frame and a half later the next frame is owed, but with the old pose it
        // waits up to a frame for a new one...
        assert_eq!(p.plan_on_thread(1.5 * dt, false).sim_frames, 0);
        assert!((p.until_due_on_thread(false) - 0.5 * dt).abs() < 1e-9);
        // ...which, when it comes, is stepped at once.
        assert_eq!(p.plan_on_thread(1.6 * dt, true).sim_frames, 1);
        // The next new pose steps the frame due at 2 dt early, at 1.7 dt...
        assert_eq!(p.plan_on_thread(1.7 * dt, true).sim_frames, 1);
        // ...and with the simulation ahead of real time, the one after waits for the next
        // pose (or its own clock) rather than start a frame late into its display period.
        assert_eq!(p.plan_on_thread(1.8 * dt, true).sim_frames, 0);
        assert!((p.until_due_on_thread(true) - 1.2 * dt).abs() < 1e-9);
        assert_eq!(p.dropped_time(), 0.0);
    }

    #[test]
    fn a_step_waits_for_the_next_pose_only_where_it_shows_at_the_same_frame() {
        let p = 1.0 / 72.0;
        // A 20 ms step spans two display periods (27.8 ms) with 7.8 ms to spare: a pose
        // 10 ms old would show at the third frame after it if started now, at the same
        // frame (two after the next pose) if started on the next pose, which comes in 3.9.
        let w = wait_for_next_pose(0.010, 0.020, p).unwrap();
        assert!((w - (p - 0.010 + ALIGN_MARGIN)).abs() < 1e-12, "{w}");
        // A pose 5 ms old: started now the step shows at the second frame; waiting would
        // make it the third.
        assert_eq!(wait_for_next_pose(0.005, 0.020, p), None);
        // Within the margin of the spare time: start now.
        assert_eq!(wait_for_next_pose(0.0085, 0.020, p), None);
        // A 6 ms step with a fresh pose: start now; with a pose 9 ms old (it would show at
        // the second frame either way), wait.
        assert_eq!(wait_for_next_pose(0.0, 0.006, p), None);
        assert!(wait_for_next_pose(0.009, 0.006, p).is_some());
        // No estimate, or a pose older than a period (the display stalled): start now.
        assert_eq!(wait_for_next_pose(0.010, 0.0, p), None);
        assert_eq!(wait_for_next_pose(0.020, 0.020, p), None);
    }
}
