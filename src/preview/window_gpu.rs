//! The window's GPU side: a surface on the render device, the 3D view drawn by the
//! incise-xr renderer straight into the swapchain image, the egui panel on top, and
//! screenshots read back from that image before it is presented.

use std::sync::Arc;

use anyhow::{Result, anyhow};
use incise_xr::{BodyState, RenderDevice, RenderSettings, Renderer, RgbaImage, View};
use winit::window::Window;

use super::display::env_set;

/// The egui output of one frame, ready to draw.
pub struct PanelFrame {
    /// Tessellated shapes.
    pub jobs: Vec<egui::ClippedPrimitive>,
    /// Font and image texture changes.
    pub textures: egui::TexturesDelta,
    /// Points → pixels.
    pub pixels_per_point: f32,
}

/// Surface, device and the egui renderer of the preview window.
pub struct WindowGpu {
    /// The device (shared with a GPU body).
    pub dev: RenderDevice,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// Whether swapchain images can be copied out (screenshots).
    can_capture: bool,
    egui: egui_wgpu::Renderer,
}

impl WindowGpu {
    /// Open a device that can present to `window`.
    pub fn new(window: Arc<Window>) -> Result<Self> {
        let size = window.inner_size();
        let (surface, dev) = match x11_instance(&window).and_then(|i| open_on(&i, &window).ok()) {
            Some(opened) => opened,
            None => open_on(&wgpu_instance(&window), &window)?,
        };
        let caps = surface.get_capabilities(&dev.adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| f.is_srgb())
            .or(caps.formats.first().copied())
            .ok_or_else(|| anyhow!("{} cannot present to this window", dev.describe()))?;
        let can_capture = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        if can_capture {
            usage |= wgpu::TextureUsages::COPY_SRC;
        }
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            desired_maximum_frame_latency: 2,
            present_mode: wgpu::PresentMode::AutoVsync,
            alpha_mode: wgpu::CompositeAlphaMode::Auto,
            view_formats: vec![],
        };
        surface.configure(&dev.device, &config);
        let egui =
            egui_wgpu::Renderer::new(&dev.device, format, egui_wgpu::RendererOptions::default());
        Ok(WindowGpu {
            dev,
            surface,
            config,
            can_capture,
            egui,
        })
    }

    /// The swapchain's colour format.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    /// The swapchain size, pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    /// Follow a window resize.
    pub fn resize(&mut self, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.dev.device, &self.config);
        }
    }

    /// Draw one frame: the body through `view`, then the panel; with `capture`, also
    /// return the finished image. `None` when no image could be acquired this time
    /// (minimised, resized under us): the caller simply tries next frame.
    pub fn draw(
        &mut self,
        renderer: &mut Renderer,
        state: &BodyState<'_>,
        settings: &RenderSettings,
        view: &View,
        panel: PanelFrame,
        capture: bool,
    ) -> Result<Option<Option<RgbaImage>>> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(None);
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.dev.device, &self.config);
                return Ok(None);
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                return Err(anyhow!("the window surface reported a validation error"));
            }
        };
        let target = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let (device, queue) = (&self.dev.device, &self.dev.queue);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("preview frame"),
        });
        renderer.prepare(&mut enc, state, settings);
        renderer.render(&mut enc, &[(*view, &target)], self.size());
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: panel.pixels_per_point,
        };
        for (id, deltas) in &panel.textures.set {
            for delta in deltas {
                self.egui.update_texture(device, queue, *id, delta);
            }
        }
        let extra = self
            .egui
            .update_buffers(device, queue, &mut enc, &panel.jobs, &screen);
        {
            let mut pass = enc
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("panel"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.egui.render(&mut pass, &panel.jobs, &screen);
        }
        for id in &panel.textures.free {
            self.egui.free_texture(id);
        }
        queue.submit(extra.into_iter().chain([enc.finish()]));
        // The surface texture stays valid until it is presented: read it back like any
        // offscreen target, then put the surface's channel order into RGBA.
        let image = if capture && self.can_capture {
            let mut img = incise_xr::offscreen::read_texture(device, queue, &frame.texture)
                .map_err(|e| anyhow!("window capture: {e}"))?;
            let bgra = matches!(
                self.config.format,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
            );
            for p in img.pixels.chunks_exact_mut(4) {
                if bgra {
                    p.swap(0, 2);
                }
                p[3] = 255;
            }
            Some(img)
        } else {
            None
        };
        queue.present(frame);
        Ok(Some(image))
    }
}

/// A surface for `window` on `instance` and a device that can present to it.
fn open_on(
    instance: &wgpu::Instance,
    window: &Arc<Window>,
) -> Result<(wgpu::Surface<'static>, RenderDevice)> {
    let surface = instance
        .create_surface(window.clone())
        .map_err(|e| anyhow!("cannot draw into the window: {e}"))?;
    let dev = pollster::block_on(RenderDevice::open(instance, Some(&surface)))?;
    Ok((surface, dev))
}

/// On X11 with no Wayland display in the environment (and no `WGPU_BACKEND` choice), a
/// Vulkan instance without the Wayland surface extension, so Mesa's device-select layer
/// does not look for a Wayland display and print "error: XDG_RUNTIME_DIR is invalid or
/// not set" (issue 34 item 3); `None` elsewhere (wgpu's own instance is used).
fn x11_instance(window: &Arc<Window>) -> Option<wgpu::Instance> {
    use winit::raw_window_handle::{HasWindowHandle, RawWindowHandle};
    let x11 = window.window_handle().is_ok_and(|h| {
        matches!(
            h.as_raw(),
            RawWindowHandle::Xlib(_) | RawWindowHandle::Xcb(_)
        )
    });
    let wayland = env_set("WAYLAND_DISPLAY") || env_set("WAYLAND_SOCKET");
    if x11 && !wayland && !env_set("WGPU_BACKEND") {
        incise_xr::vulkan_instance::x11_instance()
    } else {
        None
    }
}

/// wgpu's own instance for `window` (every backend `WGPU_BACKEND` allows).
fn wgpu_instance(window: &Arc<Window>) -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
        Box::new(window.clone()),
    ))
}
