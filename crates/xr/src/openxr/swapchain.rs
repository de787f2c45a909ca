//! An eye swapchain: one OpenXR swapchain per eye (single layer), each of its Vulkan
//! images wrapped as a wgpu texture so the renderer draws into it. One swapchain per eye
//! rather than one two-layer swapchain: on lavapipe (wgpu 30) the renderer's second
//! multisample resolve into layer 1 of an array texture lands in layer 0, so each eye
//! gets a texture of its own.

use ::openxr as xr;
use ash::vk::{self, Handle};
use wgpu::hal::{self, vulkan as hal_vk};

use super::error::{XrError, xr_call};
use crate::device::RenderDevice;

/// The eye colour format: 8-bit sRGB, as the renderer's offscreen targets.
pub const EYE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The swapchain and its images as wgpu textures.
pub struct EyeSwapchain {
    /// The OpenXR swapchain.
    pub handle: xr::Swapchain<xr::Vulkan>,
    /// Its images, wrapped (index = the acquired image index).
    pub textures: Vec<wgpu::Texture>,
    /// Eye size, pixels.
    pub size: (u32, u32),
}

impl EyeSwapchain {
    /// A swapchain for one eye at the runtime's recommended eye size.
    pub fn new(
        instance: &xr::Instance,
        system: xr::SystemId,
        session: &xr::Session<xr::Vulkan>,
        dev: &RenderDevice,
    ) -> Result<Self, XrError> {
        let views = instance
            .enumerate_view_configuration_views(system, xr::ViewConfigurationType::PRIMARY_STEREO)
            .map_err(xr_call("xrEnumerateViewConfigurationViews"))?;
        let first = views
            .first()
            .ok_or_else(|| XrError::Gpu("the runtime reports no stereo views".into()))?;
        let size = (
            first.recommended_image_rect_width,
            first.recommended_image_rect_height,
        );
        let vk_format = vk::Format::R8G8B8A8_SRGB;
        let formats = session
            .enumerate_swapchain_formats()
            .map_err(xr_call("xrEnumerateSwapchainFormats"))?;
        if !formats.contains(&(vk_format.as_raw() as u32)) {
            return Err(XrError::Gpu(
                "the runtime offers no R8G8B8A8_SRGB swapchain".into(),
            ));
        }
        let handle = session
            .create_swapchain(&xr::SwapchainCreateInfo {
                create_flags: xr::SwapchainCreateFlags::EMPTY,
                usage_flags: xr::SwapchainUsageFlags::COLOR_ATTACHMENT
                    | xr::SwapchainUsageFlags::SAMPLED,
                format: vk_format.as_raw() as u32,
                sample_count: 1,
                width: size.0,
                height: size.1,
                face_count: 1,
                array_size: 1,
                mip_count: 1,
            })
            .map_err(xr_call("xrCreateSwapchain"))?;
        let images = handle
            .enumerate_images()
            .map_err(xr_call("xrEnumerateSwapchainImages"))?;
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let mut textures = Vec::with_capacity(images.len());
        for image in images {
            // SAFETY: the image belongs to the runtime's swapchain on this device, created
            // with this format, size, one layer and these usages; the runtime owns it (a
            // drop callback that does nothing, external memory) and the swapchain
            // outlives the textures (dropped first in `XrSession`).
            let texture = unsafe {
                wrap_image(
                    dev,
                    vk::Image::from_raw(image),
                    size,
                    usage,
                    Box::new(|| {}),
                )?
            };
            textures.push(texture);
        }
        Ok(EyeSwapchain {
            handle,
            textures,
            size,
        })
    }

    /// A view of image `index`.
    pub fn view(&self, index: usize) -> wgpu::TextureView {
        self.textures[index].create_view(&wgpu::TextureViewDescriptor::default())
    }
}

/// Wrap a Vulkan image of the render device as a wgpu texture (one layer, one mip,
/// [`EYE_FORMAT`]) for `usage` (render attachment, texture binding, copy source).
///
/// # Safety
/// `image` must be a live image of `dev`'s Vulkan device created with that format,
/// `size`, one layer, one sample and the Vulkan usages matching `usage`; it must stay
/// valid until `on_drop` runs (the texture does not own its memory).
pub unsafe fn wrap_image(
    dev: &RenderDevice,
    image: vk::Image,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
    on_drop: hal::DropCallback,
) -> Result<wgpu::Texture, XrError> {
    let extent = wgpu::Extent3d {
        width: size.0,
        height: size.1,
        depth_or_array_layers: 1,
    };
    let mut uses = wgpu::TextureUses::empty();
    for (u, h) in [
        (
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            wgpu::TextureUses::COLOR_TARGET,
        ),
        (
            wgpu::TextureUsages::TEXTURE_BINDING,
            wgpu::TextureUses::RESOURCE,
        ),
        (wgpu::TextureUsages::COPY_SRC, wgpu::TextureUses::COPY_SRC),
    ] {
        if usage.contains(u) {
            uses |= h;
        }
    }
    let hal_desc = hal::TextureDescriptor {
        label: Some("xr eye image"),
        size: extent,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: EYE_FORMAT,
        usage: uses,
        memory_flags: hal::MemoryFlags::empty(),
        view_formats: vec![],
    };
    let desc = wgpu::TextureDescriptor {
        label: Some("xr eye image"),
        size: extent,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: EYE_FORMAT,
        usage,
        view_formats: &[],
    };
    // SAFETY: the caller's guarantees on `image`; the texture starts uninitialised.
    unsafe {
        let hal_device = dev
            .device
            .as_hal::<hal::api::Vulkan>()
            .ok_or_else(|| XrError::Gpu("the render device is not Vulkan".into()))?;
        let raw = hal_device.texture_from_raw(
            image,
            &hal_desc,
            Some(on_drop),
            hal_vk::TextureMemory::External,
        );
        drop(hal_device);
        Ok(dev.device.create_texture_from_hal::<hal::api::Vulkan>(
            raw,
            &desc,
            wgpu::TextureUses::UNINITIALIZED,
        ))
    }
}
