//! The OpenXR session as a [`Headset`]: events through the [`Lifecycle`], `xrWaitFrame` /
//! `xrBeginFrame` / `xrEndFrame`, views located at the predicted display time, the eye
//! swapchain, controller actions and vibration. One stereo projection layer in stage
//! space (local space where the runtime has no stage), opaque.

use ::openxr as xr;

use super::actions::{XrActions, to_pose};
use super::backdrop::Backdrop;
use super::error::{XrError, xr_call};
use super::haptics::HapticPulse;
use super::headset::{FrameEvent, Headset, HeadsetFrame};
use super::lifecycle::{Directive, Lifecycle, SessionPhase};
use super::passthrough::XrPassthrough;
use super::pose::Fov;
use super::runtime::{Runtime, open_runtime};
use super::swapchain::{EYE_FORMAT, EyeSwapchain};
use super::vulkan::{RuntimeVulkan, XrGpu, create_gpu};
use crate::device::RenderDevice;

const VIEW_TYPE: xr::ViewConfigurationType = xr::ViewConfigurationType::PRIMARY_STEREO;

/// A running OpenXR session. Fields drop in order: swapchain textures before the
/// swapchains, the session before the device, the instance last.
pub struct XrSession {
    swapchains: Option<[EyeSwapchain; 2]>,
    passthrough: Option<XrPassthrough>,
    actions: XrActions,
    stage: xr::Space,
    frame_stream: xr::FrameStream<xr::Vulkan>,
    frame_waiter: xr::FrameWaiter,
    session: xr::Session<xr::Vulkan>,
    gpu: XrGpu,
    runtime: Runtime,
    lifecycle: Lifecycle,
    events: xr::EventDataBuffer,
    frame_state: Option<xr::FrameState>,
    views: Vec<xr::View>,
    eye_size: (u32, u32),
}

fn phase(s: xr::SessionState) -> Option<SessionPhase> {
    Some(match s {
        xr::SessionState::IDLE => SessionPhase::Idle,
        xr::SessionState::READY => SessionPhase::Ready,
        xr::SessionState::SYNCHRONIZED => SessionPhase::Synchronized,
        xr::SessionState::VISIBLE => SessionPhase::Visible,
        xr::SessionState::FOCUSED => SessionPhase::Focused,
        xr::SessionState::STOPPING => SessionPhase::Stopping,
        xr::SessionState::EXITING => SessionPhase::Exiting,
        xr::SessionState::LOSS_PENDING => SessionPhase::LossPending,
        _ => return None,
    })
}

impl XrSession {
    /// Find the runtime and headset, create Vulkan through it, wrap it into wgpu and
    /// create the session. Errors for which [`XrError::is_unavailable`] holds mean no
    /// usable runtime or headset.
    pub fn open() -> Result<Self, XrError> {
        let runtime = open_runtime()?;
        let gpu = create_gpu(&RuntimeVulkan {
            instance: &runtime.instance,
            system: runtime.system,
        })?;
        // SAFETY: the handles are the live Vulkan instance, physical device and device
        // created through this runtime for this system; `gpu` outlives the session.
        let (session, frame_waiter, frame_stream) = unsafe {
            runtime.instance.create_session::<xr::Vulkan>(
                runtime.system,
                &xr::vulkan::SessionCreateInfo {
                    instance: gpu.vk_instance as _,
                    physical_device: gpu.vk_physical_device as _,
                    device: gpu.vk_device as _,
                    queue_family_index: gpu.queue_family,
                    queue_index: 0,
                },
            )
        }
        .map_err(xr_call("xrCreateSession"))?;
        let spaces = session
            .enumerate_reference_spaces()
            .map_err(xr_call("xrEnumerateReferenceSpaces"))?;
        let space_type = if spaces.contains(&xr::ReferenceSpaceType::STAGE) {
            xr::ReferenceSpaceType::STAGE
        } else {
            xr::ReferenceSpaceType::LOCAL
        };
        let stage = session
            .create_reference_space(space_type, xr::Posef::IDENTITY)
            .map_err(xr_call("xrCreateReferenceSpace"))?;
        let actions = XrActions::new(&runtime.instance, &session)?;
        let passthrough = match runtime.backdrop {
            Backdrop::Passthrough => Some(XrPassthrough::start(&session)?),
            _ => None,
        };
        let eye = runtime
            .instance
            .enumerate_view_configuration_views(runtime.system, VIEW_TYPE)
            .map_err(xr_call("xrEnumerateViewConfigurationViews"))?;
        let eye_size = eye
            .first()
            .map(|v| {
                (
                    v.recommended_image_rect_width,
                    v.recommended_image_rect_height,
                )
            })
            .unwrap_or((0, 0));
        Ok(XrSession {
            swapchains: None,
            passthrough,
            actions,
            stage,
            frame_stream,
            frame_waiter,
            session,
            gpu,
            runtime,
            lifecycle: Lifecycle::new(),
            events: xr::EventDataBuffer::new(),
            frame_state: None,
            views: Vec::new(),
            eye_size,
        })
    }

    /// Make the calls the lifecycle asks for. Calls on a session being lost may fail;
    /// those failures are not errors (the session is going away).
    fn execute(&mut self, directives: Vec<Directive>) -> Result<(), XrError> {
        for d in directives {
            match d {
                Directive::BeginSession => {
                    self.session
                        .begin(VIEW_TYPE)
                        .map_err(xr_call("xrBeginSession"))?;
                }
                Directive::EndSession => {
                    self.session.end().map_err(xr_call("xrEndSession"))?;
                }
                Directive::RequestExit => {
                    self.session
                        .request_exit()
                        .map_err(xr_call("xrRequestExitSession"))?;
                }
                Directive::ReleaseImage => {
                    for sc in self.swapchains.iter_mut().flatten() {
                        let _ = sc.handle.release_image();
                    }
                }
                Directive::EndFrame => {
                    if let Some(fs) = self.frame_state {
                        let _ = self.frame_stream.end(
                            fs.predicted_display_time,
                            self.runtime.blend_mode,
                            &[],
                        );
                    }
                }
                Directive::Quit(_) => {}
            }
        }
        Ok(())
    }

    fn poll_events(&mut self) -> Result<(), XrError> {
        loop {
            let mut directives = Vec::new();
            let more = {
                let event = self
                    .runtime
                    .instance
                    .poll_event(&mut self.events)
                    .map_err(xr_call("xrPollEvent"))?;
                match event {
                    None => false,
                    Some(xr::Event::SessionStateChanged(e)) => {
                        if let Some(p) = phase(e.state()) {
                            eprintln!("xr: session {p:?}");
                            directives = self.lifecycle.on_state(p);
                        }
                        true
                    }
                    Some(xr::Event::InstanceLossPending(_)) => {
                        directives = self.lifecycle.on_instance_loss();
                        true
                    }
                    Some(xr::Event::ReferenceSpaceChangePending(_)) => {
                        // The user recentred: poses are located in the space every frame,
                        // so the tray moves with the new origin and nothing else changes.
                        eprintln!("xr: the reference space was recentred");
                        true
                    }
                    Some(xr::Event::InteractionProfileChanged(_)) => {
                        eprintln!("xr: controllers changed");
                        true
                    }
                    Some(_) => true,
                }
            };
            self.execute(directives)?;
            if !more {
                return Ok(());
            }
        }
    }
}

impl Drop for XrSession {
    /// Let the GPU finish and release the wrapped swapchain textures (and their views)
    /// while the runtime's swapchain images still exist; the fields then drop in order.
    fn drop(&mut self) {
        let device = &self.gpu.device.device;
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        for sc in self.swapchains.iter_mut().flatten() {
            sc.textures.clear();
        }
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
    }
}

impl Headset for XrSession {
    fn device(&self) -> &RenderDevice {
        &self.gpu.device
    }

    fn eye_size(&self) -> (u32, u32) {
        self.eye_size
    }

    fn format(&self) -> wgpu::TextureFormat {
        EYE_FORMAT
    }

    fn backdrop(&self) -> Backdrop {
        self.runtime.backdrop
    }

    fn describe(&self) -> String {
        format!("{} on {}", self.runtime.name, self.gpu.device.describe())
    }

    fn next_frame(&mut self) -> Result<FrameEvent, XrError> {
        self.poll_events()?;
        if let Some(why) = self.lifecycle.finished() {
            return Ok(FrameEvent::Ended(why));
        }
        if !self.lifecycle.wants_frame() {
            std::thread::sleep(std::time::Duration::from_millis(10));
            return Ok(FrameEvent::Idle);
        }
        let fs = self.frame_waiter.wait().map_err(xr_call("xrWaitFrame"))?;
        self.frame_stream.begin().map_err(xr_call("xrBeginFrame"))?;
        self.lifecycle.begin_frame()?;
        self.frame_state = Some(fs);
        let (_, views) = self
            .session
            .locate_views(VIEW_TYPE, fs.predicted_display_time, &self.stage)
            .map_err(xr_call("xrLocateViews"))?;
        if views.len() < 2 {
            return Err(XrError::Gpu(format!(
                "the runtime located {} views, not 2",
                views.len()
            )));
        }
        self.views = views;
        let eye = |v: &xr::View| {
            (
                to_pose(v.pose),
                Fov {
                    left: v.fov.angle_left,
                    right: v.fov.angle_right,
                    up: v.fov.angle_up,
                    down: v.fov.angle_down,
                },
            )
        };
        let focused = self.lifecycle.is_focused();
        let controllers = if focused {
            self.actions
                .sample(&self.session, &self.stage, fs.predicted_display_time)?
        } else {
            Default::default()
        };
        Ok(FrameEvent::Frame(Box::new(HeadsetFrame {
            display_time: fs.predicted_display_time.as_nanos() as f64 * 1e-9,
            display_period: fs.predicted_display_period.as_nanos() as f64 * 1e-9,
            should_render: fs.should_render && self.lifecycle.is_visible(),
            eyes: [eye(&self.views[0]), eye(&self.views[1])],
            controllers,
            focused,
        })))
    }

    fn acquire(&mut self) -> Result<[wgpu::TextureView; 2], XrError> {
        if self.swapchains.is_none() {
            let make = || {
                EyeSwapchain::new(
                    &self.runtime.instance,
                    self.runtime.system,
                    &self.session,
                    &self.gpu.device,
                )
            };
            self.swapchains = Some([make()?, make()?]);
        }
        let scs = self.swapchains.as_mut().expect("created above");
        // Both eyes' images are one acquisition for the lifecycle: acquired together,
        // released together.
        let mut index = [0usize; 2];
        for (i, sc) in scs.iter_mut().enumerate() {
            index[i] = sc
                .handle
                .acquire_image()
                .map_err(xr_call("xrAcquireSwapchainImage"))? as usize;
        }
        self.lifecycle.acquire_image()?;
        for sc in scs.iter_mut() {
            sc.handle
                .wait_image(xr::Duration::INFINITE)
                .map_err(xr_call("xrWaitSwapchainImage"))?;
        }
        self.eye_size = scs[0].size;
        Ok([scs[0].view(index[0]), scs[1].view(index[1])])
    }

    fn end_frame(&mut self, rendered: bool) -> Result<(), XrError> {
        let fs = self
            .frame_state
            .ok_or_else(|| XrError::Gpu("end_frame without a frame".into()))?;
        if self.lifecycle.stage() == super::lifecycle::FrameStage::Acquired {
            for sc in self.swapchains.iter_mut().flatten() {
                sc.handle
                    .release_image()
                    .map_err(xr_call("xrReleaseSwapchainImage"))?;
            }
            self.lifecycle.release_image()?;
        }
        let result = match (&self.swapchains, rendered) {
            (Some(scs), true) => {
                let views: Vec<xr::CompositionLayerProjectionView<'_, xr::Vulkan>> = (0..2)
                    .map(|i| {
                        let rect = xr::Rect2Di {
                            offset: xr::Offset2Di { x: 0, y: 0 },
                            extent: xr::Extent2Di {
                                width: scs[i].size.0 as i32,
                                height: scs[i].size.1 as i32,
                            },
                        };
                        xr::CompositionLayerProjectionView::new()
                            .pose(self.views[i].pose)
                            .fov(self.views[i].fov)
                            .sub_image(
                                xr::SwapchainSubImage::new()
                                    .swapchain(&scs[i].handle)
                                    .image_array_index(0)
                                    .image_rect(rect),
                            )
                    })
                    .collect();
                let mut layer = xr::CompositionLayerProjection::new()
                    .space(&self.stage)
                    .views(&views);
                if self.runtime.backdrop != Backdrop::Opaque {
                    // The eye images are transparent where the room shows (premultiplied).
                    layer =
                        layer.layer_flags(xr::CompositionLayerFlags::BLEND_TEXTURE_SOURCE_ALPHA);
                }
                match &self.passthrough {
                    Some(p) => {
                        let room = p.composition_layer();
                        self.frame_stream.end(
                            fs.predicted_display_time,
                            self.runtime.blend_mode,
                            &[room.base(), &layer],
                        )
                    }
                    None => self.frame_stream.end(
                        fs.predicted_display_time,
                        self.runtime.blend_mode,
                        &[&layer],
                    ),
                }
            }
            _ => self
                .frame_stream
                .end(fs.predicted_display_time, self.runtime.blend_mode, &[]),
        };
        result.map_err(xr_call("xrEndFrame"))?;
        self.lifecycle.end_frame()?;
        Ok(())
    }

    fn vibrate(&mut self, pulse: Option<HapticPulse>) -> Result<(), XrError> {
        if self.lifecycle.is_focused() {
            self.actions.vibrate(&self.session, pulse)?;
        }
        Ok(())
    }

    fn request_exit(&mut self) -> Result<(), XrError> {
        let d = self.lifecycle.request_exit();
        self.execute(d)
    }

    fn session_states(&self) -> &[SessionPhase] {
        self.lifecycle.history()
    }
}
