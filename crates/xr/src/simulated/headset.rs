//! A headset without a runtime: the script's head and controller poses on a virtual
//! display clock, both eyes rendered offscreen (lavapipe without a GPU) into
//! one texture per eye, and a scripted session lifecycle (READY … FOCUSED at the start,
//! STOPPING → IDLE → EXITING at the end), so the XR frame loop runs unchanged.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::Vec2;
use incise_scalpel::Stroke;

use crate::offscreen::read_texture;
use crate::openxr::backdrop::Backdrop;
use crate::openxr::controls::ControllerState;
use crate::openxr::haptics::HapticPulse;
use crate::openxr::lifecycle::{FrameStage, Lifecycle, SessionPhase};
use crate::openxr::pose::XrPose;
use crate::openxr::scalpel_pose::{BladeOffset, grip_for_scalpel};
use crate::openxr::tray::Tray;
use crate::openxr::{FrameEvent, Headset, HeadsetFrame, XrError};
use crate::{RenderDevice, RenderError};

use super::script::{Button, HeadsetScript, RightTrack, XrFault, stage_pose_at, track_at};

/// Eye texture format (as the XR swapchain's).
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The simulated headset.
pub struct SimulatedHeadset {
    script: HeadsetScript,
    tool_track: Option<(f64, Stroke)>,
    tray: Tray,
    offset: BladeOffset,
    dev: RenderDevice,
    textures: [wgpu::Texture; 2],
    views: [wgpu::TextureView; 2],
    frame: u64,
    /// Display refresh of the frame begun last (= `frame` on the virtual clock).
    refresh: u64,
    /// When the wall clock started (a real-time script's first frame).
    clock: Option<Instant>,
    lifecycle: Lifecycle,
    events: VecDeque<SessionPhase>,
    stopping: bool,
    /// Faults still to come, in time order.
    faults: VecDeque<(f64, XrFault)>,
    /// Result every runtime call returns from now on (an injected lost or failed runtime).
    failing: Option<fn(&'static str) -> XrError>,
    out: PathBuf,
    /// Eye images written so far.
    pub saved: Vec<PathBuf>,
    /// Vibration pulses received (frame, amplitude).
    pub pulses: Vec<(u64, f32)>,
}

impl SimulatedHeadset {
    /// A headset playing `script`, rendering on `dev`; a `Tool` right track is carried
    /// to grip poses through `tray` and `offset`; eye images go to `out`.
    pub fn new(
        script: HeadsetScript,
        tool_stroke: Option<Stroke>,
        tray: Tray,
        offset: BladeOffset,
        dev: RenderDevice,
        out: &Path,
    ) -> Result<Self, RenderError> {
        let (w, h) = script.eye_size;
        let max = dev.limits.max_texture_dimension_2d;
        if w > max || h > max {
            return Err(RenderError::BadSize {
                width: w,
                height: h,
                why: format!("{} allows at most {max} pixels a side", dev.info.name),
            });
        }
        // One texture per eye, as the XR session's one swapchain per eye.
        let textures = [0, 1].map(|_| {
            dev.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("simulated headset eye"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        });
        let views =
            [0, 1].map(|i| textures[i].create_view(&wgpu::TextureViewDescriptor::default()));
        let start = match &script.right {
            Some(RightTrack::Tool { start, .. }) => *start,
            _ => 0.0,
        };
        let faults = script.faults.iter().copied().collect();
        Ok(SimulatedHeadset {
            faults,
            failing: None,
            tool_track: tool_stroke.map(|s| (start, s)),
            script,
            tray,
            offset,
            dev,
            textures,
            views,
            frame: 0,
            refresh: 0,
            clock: None,
            lifecycle: Lifecycle::new(),
            events: VecDeque::from([
                SessionPhase::Ready,
                SessionPhase::Synchronized,
                SessionPhase::Visible,
                SessionPhase::Focused,
            ]),
            stopping: false,
            out: out.to_path_buf(),
            saved: Vec::new(),
            pulses: Vec::new(),
        })
    }

    /// Display frames begun so far.
    pub fn frames(&self) -> u64 {
        self.frame
    }

    fn stop(&mut self) {
        if !self.stopping {
            self.stopping = true;
            self.events.extend([
                SessionPhase::Visible,
                SessionPhase::Synchronized,
                SessionPhase::Stopping,
                SessionPhase::Idle,
                SessionPhase::Exiting,
            ]);
        }
    }

    fn controllers(&self, t: f64) -> ControllerState {
        let s = &self.script;
        let right_grip = match (&s.right, &self.tool_track) {
            (Some(RightTrack::Grip(keys)), _) => stage_pose_at(keys, t),
            (Some(RightTrack::Tool { .. }), Some((start, stroke))) => {
                let rel = t - start;
                (rel >= 0.0 && rel <= stroke.end_time())
                    .then(|| grip_for_scalpel(stroke.pose_at(rel), self.offset, &self.tray))
            }
            _ => None,
        };
        let half = 0.5 * s.period();
        let pressed = |b: Button| {
            s.buttons
                .iter()
                .any(|(bt, x)| *x == b && (t - bt).abs() < half)
        };
        ControllerState {
            right_grip,
            trigger: track_at(&s.trigger, t, 0.0),
            a: pressed(Button::A),
            b: pressed(Button::B),
            left_grip: stage_pose_at(&s.left, t),
            squeeze: track_at(&s.squeeze, t, 0.0),
            stick: track_at(&s.stick, t, Vec2::ZERO),
            menu: pressed(Button::Menu),
        }
    }

    /// The display refresh the next frame is shown at. Virtual clock: the next one. Real
    /// time: the next one whose period has not begun yet (a late frame skips those it
    /// missed); refresh n's period is ((n − 1)·P, n·P], frame n renders in it.
    fn upcoming_refresh(&self) -> u64 {
        match (self.script.realtime, self.clock) {
            (false, _) => self.frame,
            (true, None) => 0,
            (true, Some(clock)) => {
                let now = clock.elapsed().as_secs_f64() / self.script.period();
                (self.refresh + 1).max(now.floor() as u64 + 1)
            }
        }
    }

    /// Wait until refresh `n`'s period begins on the wall clock (as `xrWaitFrame` does;
    /// the virtual clock does not wait).
    fn wait_for(&mut self, n: u64) {
        if !self.script.realtime {
            return;
        }
        let clock = *self.clock.get_or_insert_with(Instant::now);
        let begins = n.saturating_sub(1) as f64 * self.script.period();
        let now = clock.elapsed().as_secs_f64();
        if begins > now {
            std::thread::sleep(Duration::from_secs_f64(begins - now));
        }
    }

    /// Inject the faults due by `t`.
    fn inject_faults(&mut self, t: f64) {
        while let Some(&(at, fault)) = self.faults.front() {
            if at > t {
                break;
            }
            self.faults.pop_front();
            match fault {
                XrFault::SessionLoss => self.events.push_back(SessionPhase::LossPending),
                XrFault::InstanceLoss => {
                    let _ = self.lifecycle.on_instance_loss();
                }
                XrFault::RuntimeExit => self.stop(),
                XrFault::LostCall => {
                    self.failing = Some(XrError::session_lost);
                }
                XrFault::RuntimeFailure => {
                    self.failing = Some(XrError::runtime_failure);
                }
            }
        }
    }

    /// The injected failure of `call`, if the runtime is failing.
    fn check_failing(&self, call: &'static str) -> Result<(), XrError> {
        match self.failing {
            Some(fail) => Err(fail(call)),
            None => Ok(()),
        }
    }

    fn save_eyes(&mut self) -> Result<(), XrError> {
        for (eye, name) in [(0, "left"), (1, "right")] {
            let img = read_texture(&self.dev.device, &self.dev.queue, &self.textures[eye])?;
            let path = self.out.join(format!("eye_{name}_{:05}.png", self.frame));
            img.save_png(&path)?;
            self.saved.push(path);
        }
        Ok(())
    }
}

impl Headset for SimulatedHeadset {
    fn device(&self) -> &RenderDevice {
        &self.dev
    }

    fn eye_size(&self) -> (u32, u32) {
        self.script.eye_size
    }

    fn backdrop(&self) -> Backdrop {
        if self.script.passthrough {
            Backdrop::Passthrough
        } else {
            Backdrop::Opaque
        }
    }

    fn draws_eyes(&self) -> bool {
        self.script.draw_eyes
    }

    fn format(&self) -> wgpu::TextureFormat {
        FORMAT
    }

    fn describe(&self) -> String {
        let drawn = if self.script.draw_eyes {
            ""
        } else {
            ", eyes prepared but not drawn"
        };
        format!(
            "simulated headset ({}×{} per eye at {} Hz{drawn}) on {}",
            self.script.eye_size.0,
            self.script.eye_size.1,
            self.script.display_hz,
            self.dev.describe()
        )
    }

    fn next_frame(&mut self) -> Result<FrameEvent, XrError> {
        let refresh = self.upcoming_refresh();
        let t = refresh as f64 * self.script.period();
        // A failing runtime fails the wait for the next frame.
        self.check_failing("xrWaitFrame")?;
        if t >= self.script.duration {
            self.stop();
        }
        self.inject_faults(t);
        // Poll: every pending state change, as xrPollEvent would deliver them.
        while let Some(p) = self.events.pop_front() {
            // Begin/end session, release and end-frame calls have no runtime to go to.
            let _ = self.lifecycle.on_state(p);
        }
        if let Some(why) = self.lifecycle.finished() {
            return Ok(FrameEvent::Ended(why));
        }
        if !self.lifecycle.wants_frame() {
            return Ok(FrameEvent::Idle);
        }
        self.lifecycle.begin_frame()?;
        self.wait_for(refresh);
        self.refresh = refresh;
        let head = stage_pose_at(&self.script.head, t)
            .or_else(|| {
                let last = self.script.head.last()?;
                Some(XrPose::new(last.position, last.orientation))
            })
            .unwrap_or_default();
        let focused = self.lifecycle.is_focused();
        Ok(FrameEvent::Frame(Box::new(HeadsetFrame {
            display_time: t,
            display_period: self.script.period(),
            should_render: self.lifecycle.is_visible()
                && self.frame % self.script.render_every == 0,
            eyes: self.script.eyes(head),
            controllers: if focused {
                self.controllers(t)
            } else {
                ControllerState::default()
            },
            focused,
        })))
    }

    fn acquire(&mut self) -> Result<[wgpu::TextureView; 2], XrError> {
        self.check_failing("xrAcquireSwapchainImage")?;
        self.lifecycle.acquire_image()?;
        Ok(self.views.clone())
    }

    fn end_frame(&mut self, rendered: bool) -> Result<(), XrError> {
        self.check_failing("xrEndFrame")?;
        if self.lifecycle.stage() == FrameStage::Acquired {
            self.lifecycle.release_image()?;
        }
        if rendered && self.script.screenshots.contains(&self.frame) {
            self.save_eyes()?;
        }
        self.lifecycle.end_frame()?;
        self.frame += 1;
        Ok(())
    }

    fn vibrate(&mut self, pulse: Option<HapticPulse>) -> Result<(), XrError> {
        if let Some(p) = pulse {
            self.pulses.push((self.frame, p.amplitude));
        }
        Ok(())
    }

    fn request_exit(&mut self) -> Result<(), XrError> {
        self.stop();
        Ok(())
    }

    fn session_states(&self) -> &[SessionPhase] {
        self.lifecycle.history()
    }
}
