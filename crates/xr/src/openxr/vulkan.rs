//! The Vulkan instance and device created through the runtime (`XR_KHR_vulkan_enable2`:
//! the runtime adds the extensions it needs and picks the GPU the headset is on), wrapped
//! into wgpu through wgpu-hal so the ordinary renderer draws into the XR swapchains.
//! After openxrs `examples/vulkan.rs` and wgpu-hal 30's `Instance::from_raw` /
//! `Adapter::device_from_raw`.

use std::ffi::c_char;

use ::openxr as xr;
use ash::vk::{self, Handle};
use wgpu::hal::{self, vulkan as hal_vk};

use super::error::{XrError, xr_call};
use crate::device::RenderDevice;

/// The Vulkan version asked for (1.1: multiview is core).
const VK_VERSION: u32 = vk::API_VERSION_1_1;

/// wgpu on the runtime's Vulkan device, and the raw handles `xrCreateSession` needs.
pub struct XrGpu {
    /// The render device (wgpu).
    pub device: RenderDevice,
    /// `VkInstance`.
    pub vk_instance: u64,
    /// `VkPhysicalDevice`.
    pub vk_physical_device: u64,
    /// `VkDevice`.
    pub vk_device: u64,
    /// Queue family of wgpu's queue.
    pub queue_family: u32,
}

fn gpu_err(what: &str) -> impl Fn(String) -> XrError + '_ {
    move |e| XrError::Gpu(format!("{what}: {e}"))
}

/// Create Vulkan through the runtime for `system` and open wgpu on it.
pub fn create_gpu(instance: &xr::Instance, system: xr::SystemId) -> Result<XrGpu, XrError> {
    let reqs = instance
        .graphics_requirements::<xr::Vulkan>(system)
        .map_err(xr_call("xrGetVulkanGraphicsRequirements2KHR"))?;
    let want = xr::Version::new(1, 1, 0);
    if want < reqs.min_api_version_supported
        || want.major() > reqs.max_api_version_supported.major()
    {
        return Err(XrError::Gpu(format!(
            "the runtime needs Vulkan {} to {}; incise renders with Vulkan 1.1",
            reqs.min_api_version_supported, reqs.max_api_version_supported
        )));
    }
    // SAFETY: loads the system Vulkan loader; the handles below are created from it and
    // handed to wgpu-hal, which owns and destroys them.
    unsafe {
        let entry = ash::Entry::load().map_err(|e| gpu_err("loading libvulkan")(e.to_string()))?;
        let flags = wgpu::InstanceFlags::empty();
        let extensions = hal_vk::Instance::desired_extensions(&entry, VK_VERSION, flags)
            .map_err(|e| gpu_err("Vulkan instance extensions")(e.to_string()))?;
        let ext_ptrs: Vec<*const c_char> = extensions.iter().map(|e| e.as_ptr()).collect();
        let app = vk::ApplicationInfo::default()
            .application_name(c"incise")
            .engine_name(c"incise")
            .api_version(VK_VERSION);
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_extension_names(&ext_ptrs);
        #[allow(clippy::missing_transmute_annotations)]
        let gipa = std::mem::transmute(entry.static_fn().get_instance_proc_addr);
        let raw_instance = instance
            .create_vulkan_instance(system, gipa, &info as *const _ as *const _)
            .map_err(xr_call("xrCreateVulkanInstanceKHR"))?
            .map_err(|code| XrError::Vulkan {
                call: "vkCreateInstance",
                code,
            })?;
        let ash_instance =
            ash::Instance::load(entry.static_fn(), vk::Instance::from_raw(raw_instance as _));
        let phd_raw = instance
            .vulkan_graphics_device(system, raw_instance)
            .map_err(xr_call("xrGetVulkanGraphicsDevice2KHR"))?;
        let phd = vk::PhysicalDevice::from_raw(phd_raw as _);
        let hal_instance = hal_vk::Instance::from_raw(
            entry.clone(),
            ash_instance.clone(),
            VK_VERSION,
            0,
            None,
            extensions,
            flags,
            wgpu::MemoryBudgetThresholds::default(),
            false,
            None,
        )
        .map_err(|e| gpu_err("wgpu-hal instance")(e.to_string()))?;
        let exposed = hal_instance
            .expose_adapter(phd)
            .ok_or_else(|| XrError::Gpu("the headset's GPU cannot run wgpu".into()))?;
        // wgpu-hal opens queue family 0; it must draw.
        let families = ash_instance.get_physical_device_queue_family_properties(phd);
        let queue_family = 0;
        if !families
            .first()
            .is_some_and(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
        {
            return Err(XrError::Gpu(
                "queue family 0 of the headset's GPU cannot draw".into(),
            ));
        }
        let mut features = wgpu::Features::empty();
        for f in [wgpu::Features::TIMESTAMP_QUERY, wgpu::Features::MULTIVIEW] {
            if exposed.features.contains(f) {
                features |= f;
            }
        }
        let limits = exposed.capabilities.limits.clone();
        let dev_exts = exposed.adapter.required_device_extensions(features);
        let mut phd_features = exposed
            .adapter
            .physical_device_features(&dev_exts, features);
        let priorities = [1.0f32];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let dev_ptrs: Vec<*const c_char> = dev_exts.iter().map(|e| e.as_ptr()).collect();
        let pre = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_extension_names(&dev_ptrs);
        let dev_info = phd_features.add_to_device_create(pre);
        #[allow(clippy::missing_transmute_annotations)]
        let gipa = std::mem::transmute(entry.static_fn().get_instance_proc_addr);
        let raw_device = instance
            .create_vulkan_device(system, gipa, phd_raw, &dev_info as *const _ as *const _)
            .map_err(xr_call("xrCreateVulkanDeviceKHR"))?
            .map_err(|code| XrError::Vulkan {
                call: "vkCreateDevice",
                code,
            })?;
        let ash_device = ash::Device::load(
            ash_instance.fp_v1_0(),
            vk::Device::from_raw(raw_device as _),
        );
        let open = exposed
            .adapter
            .device_from_raw(
                ash_device,
                None,
                &dev_exts,
                features,
                &limits,
                &wgpu::MemoryHints::Performance,
                queue_family,
                0,
            )
            .map_err(|e| gpu_err("wgpu-hal device")(e.to_string()))?;
        let wgpu_instance = wgpu::Instance::from_hal::<hal::api::Vulkan>(hal_instance);
        let adapter = wgpu_instance.create_adapter_from_hal(exposed);
        let info = adapter.get_info();
        let (device, queue) = adapter
            .create_device_from_hal(
                open,
                &wgpu::DeviceDescriptor {
                    label: Some("incise xr"),
                    required_features: features,
                    required_limits: limits.clone(),
                    experimental_features: wgpu::ExperimentalFeatures::disabled(),
                    memory_hints: wgpu::MemoryHints::Performance,
                    trace: wgpu::Trace::Off,
                },
            )
            .map_err(|e| gpu_err("wgpu device")(e.to_string()))?;
        Ok(XrGpu {
            device: RenderDevice {
                adapter,
                device,
                queue,
                info,
                timestamps: features.contains(wgpu::Features::TIMESTAMP_QUERY),
                limits,
            },
            vk_instance: raw_instance as u64,
            vk_physical_device: phd_raw as u64,
            vk_device: raw_device as u64,
            queue_family,
        })
    }
}
