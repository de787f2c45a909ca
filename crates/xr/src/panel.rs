//! The panel quad's image (an exercise's result card the app rasterises): an sRGB texture
//! with its sampler and bind group (group 1 of `panel.wgsl`).

use crate::error::RenderError;

/// Format of the panel texture: 8-bit sRGB RGBA, so the shader samples linear colour.
const PANEL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The uploaded image.
struct Image {
    texture: wgpu::Texture,
    bind_group: wgpu::BindGroup,
}

/// The panel's bind group layout, sampler and current image.
pub(crate) struct Panel {
    pub layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    image: Option<Image>,
}

impl Panel {
    pub fn new(device: &wgpu::Device) -> Self {
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty,
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("panel"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    1,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("panel"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Panel {
            layout,
            sampler,
            image: None,
        }
    }

    /// The bind group of the current image, if there is one.
    pub fn bind_group(&self) -> Option<&wgpu::BindGroup> {
        self.image.as_ref().map(|i| &i.bind_group)
    }

    /// Upload `image` (RGBA8 sRGB, rows top first) or remove it (`None`). An invalid
    /// image is refused and the current one kept.
    pub fn set(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        image: Option<(&[u8], u32, u32)>,
    ) -> Result<(), RenderError> {
        let Some((bytes, width, height)) = image else {
            self.image = None;
            return Ok(());
        };
        check(
            bytes.len(),
            width,
            height,
            device.limits().max_texture_dimension_2d,
        )?;
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let reuse = self.image.take().filter(|i| i.texture.size() == size);
        let image = reuse.unwrap_or_else(|| {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("panel image"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: PANEL_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("panel"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            Image {
                texture,
                bind_group,
            }
        });
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &image.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width * 4),
                rows_per_image: Some(height),
            },
            size,
        );
        self.image = Some(image);
        Ok(())
    }
}

/// Whether `len` bytes make a `width × height` RGBA8 image a texture of at most `max`
/// pixels a side can hold.
fn check(len: usize, width: u32, height: u32, max: u32) -> Result<(), RenderError> {
    let bad = |why: String| RenderError::PanelImage { width, height, why };
    if width == 0 || height == 0 {
        return Err(bad("width and height must be at least 1 pixel".into()));
    }
    if width > max || height > max {
        return Err(bad(format!(
            "the device allows at most {max} pixels a side"
        )));
    }
    let expected = width as u64 * height as u64 * 4;
    if len as u64 != expected {
        return Err(bad(format!(
            "{len} bytes, but RGBA8 at this size is {expected}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_must_be_non_empty_within_the_limit_and_exactly_rgba8() {
        assert!(check(2 * 3 * 4, 2, 3, 8).is_ok());
        assert!(check(8 * 8 * 4, 8, 8, 8).is_ok());
        for (len, w, h) in [(0, 0, 3), (0, 2, 0), (9 * 4, 9, 1), (2 * 3 * 3, 2, 3)] {
            let e = check(len, w, h, 8).unwrap_err();
            assert!(
                matches!(e, RenderError::PanelImage { width, height, .. } if (width, height) == (w, h)),
                "{e}"
            );
        }
        let e = check(2 * 3 * 4 + 1, 2, 3, 8).unwrap_err().to_string();
        assert!(e.contains("25 bytes") && e.contains("24"), "{e}");
    }
}
