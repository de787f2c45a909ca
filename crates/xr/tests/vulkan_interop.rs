//! The XR mode's Vulkan → wgpu wrapping without an OpenXR runtime (issue 7): a Vulkan
//! instance and device created outside wgpu (as the runtime creates them) are wrapped
//! into a wgpu device through wgpu-hal, a Vulkan image created outside wgpu (as a
//! swapchain image) is wrapped as a texture, and the renderer draws a body into it.
//!
//! Without a Vulkan driver the test prints why and passes, unless the GPU is required
//! (`INCISE_REQUIRE_GPU=1`, or `CI` set with it unset).

use ash::vk;
use glam::{UVec3, Vec3};
use incise_sim::TetMesh;
use incise_sim::generate::block;
use incise_sim::skin::Skin;
use incise_test_gate::{Need, or_skip};
use incise_xr::openxr::swapchain::{EYE_FORMAT, wrap_image};
use incise_xr::openxr::vulkan::{DirectVulkan, create_gpu};
use incise_xr::{Camera, RenderSettings, Renderer, UncutBody};
use wgpu::hal;

const SIZE: (u32, u32) = (96, 64);

#[test]
fn a_foreign_vulkan_device_and_image_render_through_wgpu() {
    let Some(gpu) = or_skip(Need::Gpu, create_gpu(&DirectVulkan)) else {
        return;
    };
    assert_ne!(gpu.vk_instance, 0);
    assert_ne!(gpu.vk_device, 0);
    let dev = &gpu.device;
    assert_eq!(dev.info.backend, wgpu::Backend::Vulkan);

    // A colour image made with plain Vulkan on the wrapped device, as a runtime makes
    // swapchain images.
    let (raw_dev, image, memory) = unsafe {
        let hal_dev = dev.device.as_hal::<hal::api::Vulkan>().unwrap();
        let raw = hal_dev.raw_device().clone();
        let instance = hal_dev.shared_instance().raw_instance();
        let phd = hal_dev.raw_physical_device();
        let image = raw
            .create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(vk::Format::R8G8B8A8_SRGB)
                    .extent(vk::Extent3D {
                        width: SIZE.0,
                        height: SIZE.1,
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .tiling(vk::ImageTiling::OPTIMAL)
                    .usage(
                        vk::ImageUsageFlags::COLOR_ATTACHMENT
                            | vk::ImageUsageFlags::SAMPLED
                            | vk::ImageUsageFlags::TRANSFER_SRC,
                    )
                    .initial_layout(vk::ImageLayout::UNDEFINED),
                None,
            )
            .unwrap();
        let req = raw.get_image_memory_requirements(image);
        let props = instance.get_physical_device_memory_properties(phd);
        let index = (0..props.memory_type_count)
            .find(|&i| {
                req.memory_type_bits & (1 << i) != 0
                    && props.memory_types[i as usize]
                        .property_flags
                        .contains(vk::MemoryPropertyFlags::DEVICE_LOCAL)
            })
            .expect("a device-local memory type");
        let memory = raw
            .allocate_memory(
                &vk::MemoryAllocateInfo::default()
                    .allocation_size(req.size)
                    .memory_type_index(index),
                None,
            )
            .unwrap();
        raw.bind_image_memory(image, memory, 0).unwrap();
        (raw, image, memory)
    };
    let freed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let on_drop = {
        let (raw, freed) = (raw_dev.clone(), freed.clone());
        Box::new(move || unsafe {
            raw.destroy_image(image, None);
            raw.free_memory(memory, None);
            freed.store(true, std::sync::atomic::Ordering::SeqCst);
        })
    };
    let texture = unsafe {
        wrap_image(
            dev,
            image,
            SIZE,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            on_drop,
        )
        .unwrap()
    };
    assert_eq!(texture.format(), EYE_FORMAT);

    // Draw a small block into it with the ordinary renderer.
    let mesh = TetMesh::from_raw(block(Vec3::ZERO, Vec3::splat(0.02), UVec3::new(2, 2, 2)))
        .unwrap()
        .0;
    let skin = Skin::from_boundary(&mesh);
    let body = UncutBody::new(&mesh);
    let mut renderer = Renderer::new(&dev.device, &dev.queue, EYE_FORMAT, &mesh, &skin);
    let view = Camera::framing(Vec3::ZERO, Vec3::splat(0.02), 0.5, 0.4)
        .view(SIZE.0 as f32 / SIZE.1 as f32);
    let target = texture.create_view(&wgpu::TextureViewDescriptor::default());
    let mut enc = dev
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    renderer.prepare(
        &mut enc,
        &body.state(&mesh.rest_positions),
        &RenderSettings::default(),
    );
    renderer.render(&mut enc, &[(view, &target)], SIZE);
    let row = (SIZE.0 * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let staging = dev.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (row * SIZE.1) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        wgpu::Extent3d {
            width: SIZE.0,
            height: SIZE.1,
            depth_or_array_layers: 1,
        },
    );
    dev.queue.submit([enc.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    dev.device
        .poll(wgpu::PollType::wait_indefinitely())
        .unwrap();
    let bytes = staging.slice(..).get_mapped_range().unwrap().to_vec();
    let px = |x: u32, y: u32| {
        let i = (y * row + x * 4) as usize;
        [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]
    };
    let corner = px(0, 0);
    let centre = px(SIZE.0 / 2, SIZE.1 / 2);
    // Corner: the renderer's background; centre: the block, a different colour.
    assert_eq!(corner[3], 255, "{corner:?}");
    assert!(
        corner[..3].iter().all(|&c| c < 80),
        "dark background: {corner:?}"
    );
    assert_ne!(corner, centre, "the block is drawn in the middle");
    let drawn = (0..SIZE.1)
        .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
        .filter(|&(x, y)| px(x, y) != corner)
        .count();
    assert!(drawn > 500, "{drawn} pixels of block");

    // The wrapped image is given back through its drop callback, not freed by wgpu.
    drop((target, texture, renderer));
    dev.device
        .poll(wgpu::PollType::wait_indefinitely())
        .unwrap();
    assert!(
        freed.load(std::sync::atomic::Ordering::SeqCst),
        "drop callback ran"
    );
}
