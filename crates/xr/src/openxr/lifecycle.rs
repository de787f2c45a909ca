//! The OpenXR session lifecycle as pure code: session states in, what the app must call
//! out. The frame in flight (`xrBeginFrame` … swapchain image acquired … released …
//! `xrEndFrame`) is part of the state, so a session that stops, exits or is lost in the
//! middle of a frame first gives its swapchain image back and closes the frame.
//!
//! States follow the OpenXR 1.0 specification, "Session Lifecycle":
//! IDLE → READY (app calls `xrBeginSession`) → SYNCHRONIZED ⇄ VISIBLE ⇄ FOCUSED →
//! STOPPING (app calls `xrEndSession`) → IDLE → EXITING; LOSS_PENDING from any state.

/// An `XrSessionState` (the runtime's view of the session).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionPhase {
    /// Created, not ready to run.
    Idle,
    /// The runtime wants the app to begin the session.
    Ready,
    /// Frames are being synchronised; nothing is shown yet.
    Synchronized,
    /// Frames are shown; input goes elsewhere.
    Visible,
    /// Frames are shown and the app has input.
    Focused,
    /// The runtime wants the app to end the session.
    Stopping,
    /// The session is going away for good (user quit or app request).
    Exiting,
    /// The session was lost (headset unplugged, Link stopped).
    LossPending,
}

impl SessionPhase {
    /// Whether the OpenXR specification allows the runtime to go from `self` to `next`.
    pub fn may_become(self, next: SessionPhase) -> bool {
        use SessionPhase::*;
        matches!(
            (self, next),
            (_, LossPending)
                | (Idle, Ready | Exiting)
                | (Ready, Synchronized)
                | (Synchronized, Visible | Stopping)
                | (Visible, Focused | Synchronized)
                | (Focused, Visible)
                | (Stopping, Idle)
        ) && !matches!(self, Exiting | LossPending)
    }
}

/// Why the session ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitReason {
    /// EXITING: the user or the app quit.
    Exited,
    /// LOSS_PENDING: the runtime lost the session (headset or Link gone).
    SessionLost,
    /// `XrEventDataInstanceLossPending`: the runtime itself is going away.
    InstanceLost,
}

/// A call the app must make, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Directive {
    /// `xrBeginSession`.
    BeginSession,
    /// `xrReleaseSwapchainImage` for the image acquired this frame.
    ReleaseImage,
    /// `xrEndFrame` with no layers for the frame begun.
    EndFrame,
    /// `xrEndSession`.
    EndSession,
    /// `xrRequestExitSession` (the app wants to quit a running session).
    RequestExit,
    /// Leave the frame loop and destroy the session.
    Quit(ExitReason),
}

/// Where the app is within one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameStage {
    /// Between frames.
    Outside,
    /// `xrBeginFrame` returned; no image held.
    Begun,
    /// A swapchain image is acquired (and being rendered).
    Acquired,
}

/// A frame call made in the wrong place (a bug in the frame loop).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{call} is not allowed while the frame is {stage:?} and the session {phase:?}")]
pub struct FrameOrderError {
    /// The call.
    pub call: &'static str,
    /// The frame stage at the time.
    pub stage: FrameStage,
    /// The session phase at the time.
    pub phase: SessionPhase,
}

/// The session lifecycle and the frame in flight.
#[derive(Debug, Clone)]
pub struct Lifecycle {
    phase: SessionPhase,
    running: bool,
    stage: FrameStage,
    finished: Option<ExitReason>,
    unexpected: u32,
    history: Vec<SessionPhase>,
}

impl Default for Lifecycle {
    fn default() -> Self {
        Self::new()
    }
}

impl Lifecycle {
    /// A new session: IDLE, not running, no frame.
    pub fn new() -> Self {
        Lifecycle {
            phase: SessionPhase::Idle,
            running: false,
            stage: FrameStage::Outside,
            finished: None,
            unexpected: 0,
            history: vec![SessionPhase::Idle],
        }
    }

    /// The runtime's last reported state.
    pub fn phase(&self) -> SessionPhase {
        self.phase
    }

    /// Whether the session is begun (between `xrBeginSession` and `xrEndSession`).
    pub fn is_running(&self) -> bool {
        self.running
    }

    /// Where the frame in flight is.
    pub fn stage(&self) -> FrameStage {
        self.stage
    }

    /// Why the session ended, once it has.
    pub fn finished(&self) -> Option<ExitReason> {
        self.finished
    }

    /// State changes the specification does not allow that were seen (after lost events);
    /// they are followed anyway.
    pub fn unexpected_transitions(&self) -> u32 {
        self.unexpected
    }

    /// Every state the session has been in, in order, from the initial IDLE (the states
    /// reported after the session ended are not followed and not listed).
    pub fn history(&self) -> &[SessionPhase] {
        &self.history
    }

    /// Whether the loop should run a frame (`xrWaitFrame`) now.
    pub fn wants_frame(&self) -> bool {
        self.running && self.finished.is_none()
    }

    /// Whether frames are shown (VISIBLE or FOCUSED): render them.
    pub fn is_visible(&self) -> bool {
        matches!(self.phase, SessionPhase::Visible | SessionPhase::Focused)
    }

    /// Whether the app has input focus (FOCUSED).
    pub fn is_focused(&self) -> bool {
        self.phase == SessionPhase::Focused
    }

    /// Close the frame in flight: release its image, end it.
    fn close_frame(&mut self, out: &mut Vec<Directive>) {
        if self.stage == FrameStage::Acquired {
            out.push(Directive::ReleaseImage);
            self.stage = FrameStage::Begun;
        }
        if self.stage == FrameStage::Begun {
            out.push(Directive::EndFrame);
            self.stage = FrameStage::Outside;
        }
    }

    /// The runtime reports `next` (`XrEventDataSessionStateChanged`): the calls to make.
    pub fn on_state(&mut self, next: SessionPhase) -> Vec<Directive> {
        let mut out = Vec::new();
        if self.finished.is_some() {
            return out;
        }
        if !self.phase.may_become(next) {
            self.unexpected += 1;
        }
        self.phase = next;
        // Runtimes report the initial IDLE too; a state is listed once per change.
        if self.history.last() != Some(&next) {
            self.history.push(next);
        }
        match next {
            SessionPhase::Ready if !self.running => {
                out.push(Directive::BeginSession);
                self.running = true;
            }
            SessionPhase::Stopping => {
                self.close_frame(&mut out);
                if self.running {
                    out.push(Directive::EndSession);
                    self.running = false;
                }
            }
            SessionPhase::Exiting => {
                self.close_frame(&mut out);
                if self.running {
                    out.push(Directive::EndSession);
                    self.running = false;
                }
                out.push(Directive::Quit(ExitReason::Exited));
                self.finished = Some(ExitReason::Exited);
            }
            SessionPhase::LossPending => self.lose(ExitReason::SessionLost, &mut out),
            _ => {}
        }
        out
    }

    fn lose(&mut self, why: ExitReason, out: &mut Vec<Directive>) {
        // The runtime may refuse these calls now; they are still made so nothing is held.
        self.close_frame(out);
        self.running = false;
        out.push(Directive::Quit(why));
        self.finished = Some(why);
    }

    /// The runtime reports `XrEventDataInstanceLossPending`.
    pub fn on_instance_loss(&mut self) -> Vec<Directive> {
        let mut out = Vec::new();
        if self.finished.is_none() {
            self.lose(ExitReason::InstanceLost, &mut out);
        }
        out
    }

    /// The user asked to quit: a running session asks the runtime to stop it (and ends
    /// through STOPPING → IDLE → EXITING); one never begun ends now.
    pub fn request_exit(&mut self) -> Vec<Directive> {
        match (self.finished, self.running) {
            (Some(_), _) => vec![],
            (None, true) => vec![Directive::RequestExit],
            (None, false) => {
                self.finished = Some(ExitReason::Exited);
                vec![Directive::Quit(ExitReason::Exited)]
            }
        }
    }

    fn step(
        &mut self,
        call: &'static str,
        from: FrameStage,
        to: FrameStage,
    ) -> Result<(), FrameOrderError> {
        if self.stage != from || !self.wants_frame() {
            return Err(FrameOrderError {
                call,
                stage: self.stage,
                phase: self.phase,
            });
        }
        self.stage = to;
        Ok(())
    }

    /// `xrBeginFrame` returned.
    pub fn begin_frame(&mut self) -> Result<(), FrameOrderError> {
        self.step("xrBeginFrame", FrameStage::Outside, FrameStage::Begun)
    }

    /// A swapchain image was acquired (and waited for).
    pub fn acquire_image(&mut self) -> Result<(), FrameOrderError> {
        self.step(
            "xrAcquireSwapchainImage",
            FrameStage::Begun,
            FrameStage::Acquired,
        )
    }

    /// The image was released.
    pub fn release_image(&mut self) -> Result<(), FrameOrderError> {
        self.step(
            "xrReleaseSwapchainImage",
            FrameStage::Acquired,
            FrameStage::Begun,
        )
    }

    /// `xrEndFrame` returned.
    pub fn end_frame(&mut self) -> Result<(), FrameOrderError> {
        self.step("xrEndFrame", FrameStage::Begun, FrameStage::Outside)
    }
}

#[cfg(test)]
mod tests {
    use super::Directive::*;
    use super::SessionPhase::*;
    use super::*;

    /// A lifecycle driven to FOCUSED with a frame at `stage`.
    fn focused_at(stage: FrameStage) -> Lifecycle {
        let mut l = Lifecycle::new();
        assert_eq!(l.on_state(Ready), vec![BeginSession]);
        for p in [Synchronized, Visible, Focused] {
            assert!(l.on_state(p).is_empty());
        }
        if stage != FrameStage::Outside {
            l.begin_frame().unwrap();
        }
        if stage == FrameStage::Acquired {
            l.acquire_image().unwrap();
        }
        l
    }

    #[test]
    fn a_whole_session_through_every_state() {
        let mut l = Lifecycle::new();
        assert!(!l.wants_frame());
        assert_eq!(l.on_state(Ready), vec![BeginSession]);
        assert!(l.wants_frame() && !l.is_visible());
        assert!(l.on_state(Synchronized).is_empty());
        assert!(l.on_state(Visible).is_empty());
        assert!(l.is_visible() && !l.is_focused());
        assert!(l.on_state(Focused).is_empty());
        assert!(l.is_focused());
        // One frame, in order.
        l.begin_frame().unwrap();
        l.acquire_image().unwrap();
        l.release_image().unwrap();
        l.end_frame().unwrap();
        assert!(l.on_state(Visible).is_empty());
        assert!(l.on_state(Synchronized).is_empty());
        assert_eq!(l.request_exit(), vec![RequestExit]);
        assert_eq!(l.on_state(Stopping), vec![EndSession]);
        assert!(!l.wants_frame());
        assert!(l.on_state(Idle).is_empty());
        assert_eq!(l.on_state(Exiting), vec![Quit(ExitReason::Exited)]);
        assert_eq!(l.finished(), Some(ExitReason::Exited));
        assert_eq!(l.unexpected_transitions(), 0);
        assert_eq!(
            l.history(),
            [
                Idle,
                Ready,
                Synchronized,
                Visible,
                Focused,
                Visible,
                Synchronized,
                Stopping,
                Idle,
                Exiting
            ]
        );
        // Nothing after the end.
        assert!(l.on_state(Ready).is_empty());
        assert_eq!(l.history().len(), 10);
        assert!(l.begin_frame().is_err());
    }

    #[test]
    fn stopping_mid_frame_releases_the_image_and_ends_the_frame_first() {
        let mut l = focused_at(FrameStage::Acquired);
        // A lost-events jump straight to STOPPING while the image is held.
        assert_eq!(
            l.on_state(Stopping),
            vec![ReleaseImage, EndFrame, EndSession]
        );
        assert_eq!(l.stage(), FrameStage::Outside);
        assert_eq!(l.unexpected_transitions(), 1);
        // A session can be begun again after IDLE → READY.
        assert!(l.on_state(Idle).is_empty());
        assert_eq!(l.on_state(Ready), vec![BeginSession]);
    }

    #[test]
    fn exiting_and_loss_pending_mid_frame_never_leave_an_image_acquired() {
        let stages = [FrameStage::Outside, FrameStage::Begun, FrameStage::Acquired];
        for stage in stages {
            for event in [Some(Exiting), Some(LossPending), None] {
                let mut l = focused_at(stage);
                let out = match event {
                    Some(p) => l.on_state(p),
                    None => l.on_instance_loss(),
                };
                // Acquired images are released before the frame ends, the frame ends
                // before the session, and quitting comes last.
                let mut expected = Vec::new();
                if stage == FrameStage::Acquired {
                    expected.push(ReleaseImage);
                }
                if stage != FrameStage::Outside {
                    expected.push(EndFrame);
                }
                if event == Some(Exiting) {
                    expected.push(EndSession);
                }
                let why = match event {
                    Some(Exiting) => ExitReason::Exited,
                    Some(_) => ExitReason::SessionLost,
                    None => ExitReason::InstanceLost,
                };
                expected.push(Quit(why));
                assert_eq!(out, expected, "{stage:?} {event:?}");
                assert_eq!(l.stage(), FrameStage::Outside);
                assert!(!l.is_running() && !l.wants_frame());
                assert_eq!(l.finished(), Some(why));
                // The loop's own release/end after the fact is refused, not repeated.
                assert!(l.release_image().is_err() && l.end_frame().is_err());
            }
        }
    }

    #[test]
    fn frame_calls_out_of_order_are_refused() {
        let mut l = Lifecycle::new();
        assert!(l.begin_frame().is_err(), "not running");
        let mut l = focused_at(FrameStage::Outside);
        assert!(l.acquire_image().is_err());
        assert!(l.end_frame().is_err());
        l.begin_frame().unwrap();
        assert!(l.begin_frame().is_err());
        l.acquire_image().unwrap();
        let e = l.end_frame().unwrap_err();
        assert_eq!(e.stage, FrameStage::Acquired);
        assert!(e.to_string().contains("xrEndFrame"));
    }

    #[test]
    fn quitting_before_the_session_ran_and_the_transition_table() {
        let mut l = Lifecycle::new();
        assert_eq!(l.request_exit(), vec![Quit(ExitReason::Exited)]);
        assert!(l.request_exit().is_empty());
        assert!(Idle.may_become(Ready) && Idle.may_become(Exiting));
        assert!(!Idle.may_become(Focused) && !Ready.may_become(Stopping));
        assert!(Focused.may_become(LossPending) && !Exiting.may_become(LossPending));
        assert!(!Focused.may_become(Stopping));
    }
}
