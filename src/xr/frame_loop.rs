//! The headset's display loop, one for every method and for the OpenXR session and the
//! simulated headset alike: per display frame, controller input → the tray and the tool
//! command (the scalpel pose sampled at the frame's predicted display time, trigger, A,
//! pause, heat map), the simulation advanced ([`HeadsetSim`]: in the frame or on its own
//! thread), vibration from the tool force, both eyes drawn from the newest picture into
//! the headset's targets, and a frame-time row.

use std::time::Instant;

use anyhow::Result;
use glam::Mat4;
use incise_xr::frame::ToolState;
use incise_xr::openxr::controls::{ControllerState, commands};
use incise_xr::openxr::eye::eye_view;
use incise_xr::openxr::frame_log::{FrameLog, FrameRow};
use incise_xr::openxr::haptics::{HapticCall, HapticGate, haptic_pulse};
use incise_xr::openxr::lifecycle::{ExitReason, SessionPhase};
use incise_xr::openxr::scalpel_pose::{BladeOffset, scalpel_pose};
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{FrameEvent, Headset, HeadsetFrame, XrError};
use incise_xr::{Overlays, RenderDevice, RenderSettings};

use super::command::{Advanced, ToolCommand};
use super::headset_sim::{HeadsetSim, Picture};

/// `Idle` answers in a row after which the loop gives up (about 10 s of a runtime that
/// never makes the session ready).
pub const MAX_IDLE: u32 = 1000;

/// How the display loop runs.
pub struct DisplayOptions<'a> {
    /// Stop after this many display frames (asks the session to exit).
    pub max_frames: Option<u64>,
    /// Where the blade sits on the right controller.
    pub blade: BladeOffset,
    /// Tool force (N) → vibration amplitude (0..1): the scalpel's haptic curve.
    pub haptic: &'a dyn Fn(f32) -> f32,
    /// The tray at the start.
    pub tray: Tray,
    /// A played stroke holds the blade engaged instead of the trigger.
    pub played: bool,
}

/// What the display loop did.
pub struct DisplayOutcome {
    /// Display frames run.
    pub frames: u64,
    /// Display frames rendered.
    pub rendered: u64,
    /// Of those, the ones whose eyes were drawn (all unless the headset draws none).
    pub drawn: u64,
    /// Wall time of the loop, s.
    pub wall_s: f64,
    /// How the session ended (`None`: the runtime never made it ready).
    pub exit: Option<ExitReason>,
    /// Whether Ctrl-C (or SIGTERM) ended it.
    pub interrupted: bool,
    /// Vibration pulses sent (`xrApplyHapticFeedback`).
    pub haptic_pulses: u64,
    /// Vibration stops sent (`xrStopHapticFeedback`): one each time the vibration ended,
    /// and one at the end if it was still vibrating.
    pub haptic_stops: u64,
    /// The session states, in order.
    pub session_states: Vec<SessionPhase>,
    /// Per-frame times.
    pub log: FrameLog,
    /// The failure that stopped the session, when it did not end cleanly (the outputs
    /// above are still complete up to it).
    pub error: Option<anyhow::Error>,
}

/// Run the display loop on `headset` with `sim` until the session ends; the simulation
/// is told the session is over ([`HeadsetSim::end`]) however it ended.
pub fn drive(
    headset: &mut dyn Headset,
    sim: &mut dyn HeadsetSim,
    opts: &DisplayOptions<'_>,
) -> DisplayOutcome {
    let mut display = Display {
        dev: headset.device().clone(),
        headset,
        opts,
        tray: opts.tray,
        previous: ControllerState::default(),
        paused: false,
        heat_map: sim.heat_map_at_start(),
        haptics: HapticGate::default(),
        exit_asked: false,
        out: DisplayOutcome {
            frames: 0,
            rendered: 0,
            drawn: 0,
            wall_s: 0.0,
            exit: None,
            interrupted: false,
            haptic_pulses: 0,
            haptic_stops: 0,
            session_states: Vec::new(),
            log: FrameLog::default(),
            error: None,
        },
    };
    let started = Instant::now();
    let ended = sim.start().and_then(|()| display.frames(sim));
    display.out.wall_s = started.elapsed().as_secs_f64();
    display.finish(ended, sim)
}

/// What a display frame showed: whether it rendered, the vibration amplitude sent, its
/// tool-to-tissue latency (ms, rendered frames).
struct Shown {
    rendered: bool,
    haptic: f32,
    tool_latency_ms: Option<f64>,
}

/// The display side of a session.
struct Display<'h, 'o> {
    headset: &'h mut dyn Headset,
    dev: RenderDevice,
    opts: &'o DisplayOptions<'o>,
    tray: Tray,
    previous: ControllerState,
    paused: bool,
    heat_map: bool,
    haptics: HapticGate,
    exit_asked: bool,
    out: DisplayOutcome,
}

impl Display<'_, '_> {
    /// Display frames until the session ends, or the runtime answered Idle [`MAX_IDLE`]
    /// times in a row.
    fn frames(&mut self, sim: &mut dyn HeadsetSim) -> Result<()> {
        let mut idle = 0;
        loop {
            let frame = match self.headset.next_frame()? {
                FrameEvent::Ended(why) => {
                    self.out.exit = Some(why);
                    return Ok(());
                }
                FrameEvent::Idle => {
                    // Ctrl-C before the runtime runs the session (or between runs): the
                    // lifecycle ends a session that is not running at once.
                    self.maybe_exit(false)?;
                    idle += 1;
                    if idle > MAX_IDLE {
                        return Ok(());
                    }
                    continue;
                }
                FrameEvent::Frame(f) => *f,
            };
            idle = 0;
            self.frame(&frame, sim)?;
            let limit = self.opts.max_frames.is_some_and(|m| self.out.frames >= m);
            self.maybe_exit(limit || sim.stroke_done())?;
        }
    }

    /// One display frame (logged also when ending it failed: its simulation was stepped).
    fn frame(&mut self, frame: &HeadsetFrame, sim: &mut dyn HeadsetSim) -> Result<()> {
        let started = Instant::now();
        let cmd = self.input(frame, sim)?;
        let adv = sim.advance(frame, &cmd)?;
        let sent = self.vibrate(adv.tool_force, sim.vibrates(&cmd), frame.display_period)?;
        let render_start = Instant::now();
        let drawn = match frame.should_render {
            true => self.render(frame, sim),
            false => Ok(false),
        };
        let rendered = matches!(drawn, Ok(true));
        let ended = match drawn {
            Ok(false) => self.headset.end_frame(false).map_err(anyhow::Error::from),
            Ok(true) => Ok(()),
            Err(e) => Err(e),
        };
        let shown = Shown {
            rendered,
            haptic: sent,
            tool_latency_ms: (sim.shown_command())
                .filter(|_| rendered)
                .map(|(_, t)| (frame.display_time - t) * 1e3),
        };
        self.log(frame, &adv, &cmd, shown, [started, render_start]);
        sim.after_frame();
        ended
    }

    /// Controller input: the buttons, the tray, and the frame's tool command.
    fn input(&mut self, frame: &HeadsetFrame, sim: &mut dyn HeadsetSim) -> Result<ToolCommand> {
        let c = frame.controllers;
        let pressed = commands(&self.previous, &c);
        self.previous = c;
        if pressed.reset {
            sim.on_a()?;
        }
        self.heat_map ^= pressed.toggle_stress;
        self.paused ^= pressed.toggle_pause;
        if let (true, Some(grip)) = (c.moving_tray(), c.left_grip) {
            self.tray = self.tray.placed_at(grip);
        }
        self.tray = self.tray.steered(c.stick, frame.display_period as f32);
        Ok(ToolCommand {
            frame: self.out.frames,
            display_time: frame.display_time,
            // Sampled by the headset at the predicted display time.
            pose: c
                .right_grip
                .map(|g| scalpel_pose(g, self.opts.blade, &self.tray)),
            engaged: self.opts.played || c.blade_engaged(),
            paused: self.paused,
            resets: 0,
        })
    }

    /// The vibration for tool force `force` while the tool `vibrates`; the amplitude
    /// sent.
    fn vibrate(&mut self, force: f32, vibrates: bool, period: f64) -> Result<f32> {
        let amplitude = (self.opts.haptic)(force);
        let pulse = haptic_pulse(amplitude, vibrates, period);
        match self.haptics.send(pulse, |p| self.headset.vibrate(p))? {
            HapticCall::Apply(_) => self.out.haptic_pulses += 1,
            HapticCall::Stop => self.out.haptic_stops += 1,
            HapticCall::Nothing => {}
        }
        Ok(pulse.map_or(0.0, |p| p.amplitude))
    }

    /// Both eyes into the headset's targets from the simulation's picture (the frame
    /// ended with them); false when there is none to show yet.
    fn render(&mut self, frame: &HeadsetFrame, sim: &mut dyn HeadsetSim) -> Result<bool> {
        let head = (frame.eyes[0].0.position + frame.eyes[1].0.position) * 0.5;
        let Some(picture) = sim.picture(&self.tray, head)? else {
            return Ok(false);
        };
        let targets = self.headset.acquire()?;
        let stage_from_sim = self.tray.stage_from_sim();
        let views = frame
            .eyes
            .map(|(pose, fov)| eye_view(pose, fov, stage_from_sim));
        let settings = self.settings(&picture);
        let mut enc = self
            .dev
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("xr frame"),
            });
        picture.renderer.prepare(&mut enc, &picture.body, &settings);
        if self.headset.draws_eyes() {
            picture.renderer.render(
                &mut enc,
                &[(views[0], &targets[0]), (views[1], &targets[1])],
                self.headset.eye_size(),
            );
            self.dev.queue.submit([enc.finish()]);
            self.out.drawn += 1;
        } else {
            // The uploads go (they are the host's part); the skinning and the drawing
            // recorded in `enc` are a GPU's, and are dropped.
            self.dev.queue.submit([]);
        }
        self.headset.end_frame(true)?;
        self.out.rendered += 1;
        Ok(true)
    }

    fn settings(&self, picture: &Picture<'_>) -> RenderSettings {
        let (background, background_alpha) = self.headset.backdrop().clear();
        RenderSettings {
            lines: picture.lines.clone(),
            panel: picture.panel,
            stress_max: picture.heat_max,
            tool: ToolState {
                transform: (picture.tool)
                    .map(|pose| Mat4::from_rotation_translation(pose.rotation, pose.position)),
                spheres: vec![],
            },
            overlays: Overlays {
                stress: self.heat_map,
                ..Default::default()
            },
            background,
            background_alpha,
            ..RenderSettings::default()
        }
    }

    /// The frame's row; `clock`: when the frame and its rendering started.
    fn log(
        &mut self,
        frame: &HeadsetFrame,
        adv: &Advanced,
        cmd: &ToolCommand,
        shown: Shown,
        clock: [Instant; 2],
    ) {
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        self.out.log.rows.push(FrameRow {
            frame: self.out.frames,
            display_time: frame.display_time,
            sim_frames: adv.sim_frames,
            substeps: adv.substeps,
            sim_ms: adv.sim_ms,
            render_ms: ms(clock[1]),
            frame_ms: ms(clock[0]),
            rendered: shown.rendered,
            engaged: cmd.engaged,
            tool_force: adv.tool_force,
            haptic: shown.haptic,
            display_period: frame.display_period,
            tool_latency_ms: shown.tool_latency_ms,
        });
        self.out.frames += 1;
    }

    /// Ctrl-C ends the session the way the runtime expects (xrRequestExitSession), so the
    /// files are saved as after any other end; so does reaching the `end` (the frame
    /// limit, a played stroke's end). Asked once.
    fn maybe_exit(&mut self, end: bool) -> Result<()> {
        let interrupted = crate::interrupt::requested();
        if !self.exit_asked && (interrupted || end) {
            self.exit_asked = true;
            self.out.interrupted = interrupted;
            self.headset.request_exit()?;
        }
        Ok(())
    }

    /// The outcome, however the session `ended`.
    fn finish(self, ended: Result<()>, sim: &mut dyn HeadsetSim) -> DisplayOutcome {
        let Display {
            mut out,
            headset,
            haptics,
            ..
        } = self;
        // An attempt the blade touched is scored and saved however the session ended.
        let ended = match (ended, sim.end()) {
            (Ok(()), saved) => saved,
            (Err(e), Ok(())) => Err(e),
            (Err(e), Err(s)) => {
                eprintln!("xr: saving the attempt failed: {s:#}");
                Err(e)
            }
        };
        if let Err(e) = ended {
            match e.downcast_ref::<XrError>().and_then(XrError::lost) {
                // The runtime lost the session or is going away: a clean end, as on the
                // LOSS_PENDING event.
                Some(why) => {
                    eprintln!("xr: {e:#}: the session is over");
                    out.exit = Some(why);
                }
                None => out.error = Some(e),
            }
        }
        // The controller may be gone with the session: stopping its vibration can fail.
        if haptics.vibrating() && headset.vibrate(None).is_ok() {
            out.haptic_stops += 1;
        }
        out.session_states = headset.session_states().to_vec();
        out
    }
}
