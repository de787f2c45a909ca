//! The multisampled colour and depth attachments a frame is drawn into before it is
//! resolved into the caller's target, kept while the size and format stay the same.

use crate::pipelines::{DEPTH_FORMAT, SAMPLES};

/// MSAA colour and depth for one view size.
pub(crate) struct Attachments {
    pub size: (u32, u32),
    pub colour: wgpu::TextureView,
    pub depth: wgpu::TextureView,
}

impl Attachments {
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat, size: (u32, u32)) -> Self {
        let make = |label, format| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width: size.0,
                        height: size.1,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: SAMPLES,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        Attachments {
            size,
            colour: make("msaa colour", format),
            depth: make("msaa depth", DEPTH_FORMAT),
        }
    }
}
