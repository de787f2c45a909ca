//! Rendering without a window: into one texture per eye that can be read back
//! as an image — screenshots, golden-image tests and the benchmark.

use incise_sim::TetMesh;
use incise_sim::skin::Skin;

use crate::camera::View;
use crate::device::RenderDevice;
use crate::error::RenderError;
use crate::frame::{BodyState, RenderSettings};
use crate::image_io::RgbaImage;
use crate::renderer::{Renderer, read_buffer};

/// Colour format of offscreen images: 8-bit sRGB.
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// A renderer with its own target textures, one per eye. (One texture per eye, not the
/// layers of an array texture: on lavapipe a pass into layer 1 of a 2-layer texture
/// wrote into layer 0, leaving the second eye blank.)
pub struct OffscreenRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// The renderer (for timing and skin readback).
    pub renderer: Renderer,
    size: (u32, u32),
    textures: Vec<wgpu::Texture>,
    layer_views: Vec<wgpu::TextureView>,
}

impl OffscreenRenderer {
    /// A `width × height` target with `layers` eyes (1 for a camera, 2 for stereo).
    pub fn new(
        dev: &RenderDevice,
        mesh: &TetMesh,
        skin: &Skin,
        (width, height): (u32, u32),
        layers: u32,
    ) -> Result<Self, RenderError> {
        let max = dev.limits.max_texture_dimension_2d;
        let bad = |why: String| RenderError::BadSize { width, height, why };
        if width == 0 || height == 0 {
            return Err(bad("width and height must be at least 1 pixel".into()));
        }
        if width > max || height > max {
            return Err(bad(format!(
                "{} allows at most {max} pixels a side",
                dev.info.name
            )));
        }
        if !(1..=4).contains(&layers) {
            return Err(bad(format!("1 to 4 eyes, not {layers}")));
        }
        let textures: Vec<wgpu::Texture> = (0..layers)
            .map(|_| {
                dev.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("offscreen target"),
                    size: wgpu::Extent3d {
                        width,
                        height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: OFFSCREEN_FORMAT,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                })
            })
            .collect();
        let layer_views = textures
            .iter()
            .map(|t| t.create_view(&wgpu::TextureViewDescriptor::default()))
            .collect();
        Ok(OffscreenRenderer {
            renderer: Renderer::new(&dev.device, &dev.queue, OFFSCREEN_FORMAT, mesh, skin),
            device: dev.device.clone(),
            queue: dev.queue.clone(),
            size: (width, height),
            textures,
            layer_views,
        })
    }

    /// Target size, pixels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Width / height.
    pub fn aspect(&self) -> f32 {
        self.size.0 as f32 / self.size.1 as f32
    }

    /// Draw one frame: `views[i]` into layer `i` (extra views are ignored). Submits and
    /// returns without waiting.
    pub fn render(&mut self, state: &BodyState<'_>, settings: &RenderSettings, views: &[View]) {
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("offscreen frame"),
            });
        self.renderer.prepare(&mut enc, state, settings);
        let pairs: Vec<(View, &wgpu::TextureView)> =
            views.iter().copied().zip(&self.layer_views).collect();
        self.renderer.render(&mut enc, &pairs, self.size);
        self.queue.submit([enc.finish()]);
    }

    /// Wait until the device has finished every submitted frame.
    pub fn wait(&self) -> Result<(), RenderError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| RenderError::Readback(e.to_string()))
    }

    /// Read eye `layer`'s target back as an image (waits for the device).
    pub fn read_image(&self, layer: u32) -> Result<RgbaImage, RenderError> {
        let texture = self.textures.get(layer as usize).ok_or_else(|| {
            RenderError::Readback(format!(
                "no eye {layer}: the target has {}",
                self.textures.len()
            ))
        })?;
        read_texture(&self.device, &self.queue, texture)
    }

    /// Render one view into layer 0 and read it back.
    pub fn render_image(
        &mut self,
        state: &BodyState<'_>,
        settings: &RenderSettings,
        view: &View,
    ) -> Result<RgbaImage, RenderError> {
        self.render(state, settings, std::slice::from_ref(view));
        self.read_image(0)
    }
}

/// Read a whole single-layer RGBA8 `texture` back as an image (waits for the device):
/// offscreen targets and the simulated headset's eye textures.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<RgbaImage, RenderError> {
    let (w, h) = (texture.width(), texture.height());
    let row = (w * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("image readback"),
        size: row as u64 * h as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([enc.finish()]);
    let bytes = read_buffer(device, &staging)?;
    let mut pixels = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h as usize {
        let start = y * row as usize;
        pixels.extend_from_slice(&bytes[start..start + w as usize * 4]);
    }
    Ok(RgbaImage {
        width: w,
        height: h,
        pixels,
    })
}
