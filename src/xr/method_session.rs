//! The headset session for a scene of any method ([`DrawnBody`]): the organ on the tray,
//! stepped inside each display frame to the frame's display time, with the scene's own
//! script (the Nakao blade's stroke, the rheology indenter) until the right controller's
//! trigger takes the tool: then the scalpel cuts (Nakao) or presses (rheology) where the
//! controller holds it, vibrating with the method's tool force where it has one. Both
//! eyes show the heat map of the method's own quantity. Writes the body's `report.json`
//! (the run's schema) into the output folder.

use std::path::Path;

use anyhow::{Context, Result};
use incise_scalpel::HapticCurve;
use incise_xr::openxr::haptics::haptic_pulse;
use incise_xr::openxr::scalpel_pose::{BladeOffset, scalpel_pose};
use incise_xr::openxr::tray::Tray;
use incise_xr::openxr::{FrameEvent, Headset, HeadsetFrame, eye::eye_view};
use incise_xr::{Overlays, RenderDevice, RenderSettings, Renderer};

use super::script::{HeadsetScript, RightTrack};
use super::simulated::SimulatedHeadset;
use crate::pictures::drawn_body::DrawnBody;
use crate::sim_body::ToolInput;

/// What a method session did.
struct Session {
    body: DrawnBody,
    renderer: Renderer,
    tray: Tray,
    /// Whether the controller has taken the tool from the scene's script.
    hand: bool,
    /// The display time of the first frame, s (simulated time 0).
    start: Option<f64>,
    frames: u64,
    rendered: u64,
    pulses: u64,
    haptic: HapticCurve,
}

/// Run `scene` (any method but XPBD) on the simulated headset playing `script_path`,
/// writing eye images and `report.json` to `out`; the session's summary line.
pub fn run_simulated(scene: &Path, script_path: &Path, out: &Path) -> Result<String> {
    let script = HeadsetScript::load(script_path)?;
    let dev = RenderDevice::headless()?;
    let body = DrawnBody::open(scene)?;
    let (lo, hi) = body.drawing.render.mesh.rest_bounds();
    let tray = Tray::for_bounds(lo, hi);
    let stroke = tool_stroke(&script, script_path)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let offset = BladeOffset::default();
    let mut headset = SimulatedHeadset::new(script, stroke, tray, offset, dev, out)?;
    run_on(&mut headset, scene, body, tray, out)
}

/// Run the opened `body` of `scene` on `headset` with the organ on `tray`; writes
/// `report.json` to `out`; the session's summary line.
pub fn run_on(
    headset: &mut dyn Headset,
    scene: &Path,
    body: DrawnBody,
    tray: Tray,
    out: &Path,
) -> Result<String> {
    let dev = headset.device().clone();
    let renderer = renderer_for(&dev, headset.format(), &body);
    let mut s = Session {
        body,
        renderer,
        tray,
        hand: false,
        start: None,
        frames: 0,
        rendered: 0,
        pulses: 0,
        haptic: HapticCurve::default(),
    };
    while let Some(frame) = next(headset)? {
        s.frame(headset, &dev, &frame)?;
    }
    let (frames, rendered, pulses) = (s.frames, s.rendered, s.pulses);
    let summary = s.body.close(Some(&out.join("report.json")))?;
    Ok(format!(
        "{} on {}: {frames} display frames ({rendered} rendered), {pulses} vibration pulses; {summary}",
        scene.display(),
        headset.describe()
    ))
}

/// The next begun frame, `None` when the session has ended.
fn next(headset: &mut dyn Headset) -> Result<Option<HeadsetFrame>> {
    loop {
        match headset.next_frame()? {
            FrameEvent::Frame(f) => return Ok(Some(*f)),
            FrameEvent::Idle => continue,
            FrameEvent::Ended(_) => return Ok(None),
        }
    }
}

/// The scripted right-hand stroke, drawn with the built-in scalpel.
fn tool_stroke(script: &HeadsetScript, path: &Path) -> Result<Option<incise_scalpel::Stroke>> {
    let Some(RightTrack::Tool { stroke, .. }) = &script.right else {
        return Ok(None);
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(Some(match stroke {
        crate::scene::ToolStroke::File(f) => incise_scalpel::load_stroke(&dir.join(f))?,
        crate::scene::ToolStroke::Incision(i) => {
            crate::scene::incision(&crate::scene::hand_tool::default_tool()?, i)
                .with_context(|| format!("{}: right.stroke", path.display()))?
        }
    }))
}

impl Session {
    /// One display frame: step the body up to the frame's display time with the tool,
    /// vibrate, draw both eyes.
    fn frame(
        &mut self,
        headset: &mut dyn Headset,
        dev: &RenderDevice,
        f: &HeadsetFrame,
    ) -> Result<()> {
        self.frames += 1;
        let start = *self.start.get_or_insert(f.display_time);
        let tool = self.tool(f);
        let dt = self.body.body.frame_dt();
        while self.body.body.time() + 0.5 * dt < f.display_time - start {
            if self.body.step(&tool).map_err(anyhow::Error::msg)? {
                self.renderer = renderer_for(dev, headset.format(), &self.body);
            }
        }
        let force = self.body.body.tool_force().map_or(0.0, |v| v.length());
        let pulse = haptic_pulse(self.haptic.amplitude(force), self.hand, f.display_period);
        if pulse.is_some() {
            self.pulses += 1;
        }
        headset.vibrate(pulse)?;
        if !f.should_render {
            return Ok(headset.end_frame(false)?);
        }
        let targets = headset.acquire()?;
        let stage_from_sim = self.tray.stage_from_sim();
        let views = f
            .eyes
            .map(|(pose, fov)| eye_view(pose, fov, stage_from_sim));
        let (background, background_alpha) = headset.backdrop().clear();
        let settings = RenderSettings {
            overlays: Overlays {
                stress: true,
                ..Overlays::default()
            },
            stress_max: self.body.drawing.scale,
            background,
            background_alpha,
            ..RenderSettings::default()
        };
        let mut enc = dev
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("xr method frame"),
            });
        self.renderer
            .prepare(&mut enc, &self.body.state(), &settings);
        self.renderer.render(
            &mut enc,
            &[(views[0], &targets[0]), (views[1], &targets[1])],
            headset.eye_size(),
        );
        dev.queue.submit([enc.finish()]);
        headset.end_frame(true)?;
        self.rendered += 1;
        Ok(())
    }

    /// The frame's tool: the scene's script until the trigger engages the controller's.
    fn tool(&mut self, f: &HeadsetFrame) -> ToolInput {
        let c = f.controllers;
        self.hand |= c.blade_engaged() && c.right_grip.is_some();
        match (self.hand, c.right_grip) {
            (true, Some(grip)) => ToolInput::Hand {
                pose: scalpel_pose(grip, BladeOffset::default(), &self.tray),
                engaged: c.blade_engaged(),
            },
            _ => ToolInput::Script,
        }
    }
}

/// A renderer for the body's current topology.
fn renderer_for(dev: &RenderDevice, format: wgpu::TextureFormat, body: &DrawnBody) -> Renderer {
    let r = &body.drawing.render;
    Renderer::new(&dev.device, &dev.queue, format, &r.mesh, &r.skin)
}
