//! The Vulkan instance and device, created through the runtime (`XR_KHR_vulkan_enable2`:
//! the runtime adds the extensions it needs and picks the GPU the headset is on) and
//! wrapped into wgpu through wgpu-hal, so the ordinary renderer draws into the XR
//! swapchains. After openxrs `examples/vulkan.rs` and wgpu-hal 30's
//! `Instance::from_raw` / `Adapter::device_from_raw`.
//!
//! Who creates the three Vulkan objects is a [`VulkanCreator`]: [`RuntimeVulkan`] for a
//! session, [`DirectVulkan`] (plain `vkCreateInstance`/`vkCreateDevice`, first device) to
//! check the wgpu wrapping on any Vulkan driver without a runtime.

use std::ffi::c_char;

use ::openxr as xr;
use ash::vk::{self, Handle};
use incise_sim::gpu::OpenedDevice;
use wgpu::hal::{self, vulkan as hal_vk};

use super::error::{XrError, xr_call};
use crate::device::RenderDevice;
use crate::vulkan_instance::{application_info, instance_version};

/// The Vulkan API version the app is written for, as wgpu-hal 30 asks it (1.3): with a
/// lower one, wgpu-hal would still call the 1.2 core functions of a 1.3 device (timeline
/// semaphores) that the instance then lacks.
pub const VK_VERSION: u32 = vk::API_VERSION_1_3;

/// Check Vulkan `want` against the runtime's requirements: below its minimum is an error;
/// above the highest version it was tested with (`maxApiVersionSupported`) the OpenXR
/// specification lets the app go on, so that is a warning (returned).
pub fn check_vulkan_version(
    want: xr::Version,
    min: xr::Version,
    max: xr::Version,
) -> Result<Option<String>, XrError> {
    if want < min {
        return Err(XrError::Gpu(format!(
            "the runtime needs Vulkan {min} or newer; incise renders with Vulkan {want} (wgpu 30)"
        )));
    }
    Ok((want > max).then(|| {
        format!(
            "the runtime was tested with Vulkan up to {max}; incise asks for Vulkan {want} (wgpu 30) and goes on, but the runtime may not work with it"
        )
    }))
}

/// Creates the Vulkan instance, picks the physical device and creates the device.
pub trait VulkanCreator {
    /// Create the instance from `info` (the creator may add extensions).
    ///
    /// # Safety
    /// `info` must be a valid create-info whose pointers live for the call.
    unsafe fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo<'_>,
    ) -> Result<vk::Instance, XrError>;
    /// The physical device to render on.
    ///
    /// # Safety
    /// `instance` must have been created by `create_instance` from `entry`.
    unsafe fn physical_device(
        &self,
        instance: &ash::Instance,
    ) -> Result<vk::PhysicalDevice, XrError>;
    /// Create the device from `info` (the creator may add extensions).
    ///
    /// # Safety
    /// `phd` must come from `instance`; `info` must be valid for the call.
    unsafe fn create_device(
        &self,
        entry: &ash::Entry,
        instance: &ash::Instance,
        phd: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo<'_>,
    ) -> Result<vk::Device, XrError>;
}

/// Vulkan through the OpenXR runtime (`xrCreateVulkanInstanceKHR`,
/// `xrGetVulkanGraphicsDevice2KHR`, `xrCreateVulkanDeviceKHR`).
pub struct RuntimeVulkan<'a> {
    /// The instance (with `XR_KHR_vulkan_enable2`).
    pub instance: &'a xr::Instance,
    /// The headset.
    pub system: xr::SystemId,
}

impl VulkanCreator for RuntimeVulkan<'_> {
    unsafe fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo<'_>,
    ) -> Result<vk::Instance, XrError> {
        let reqs = self
            .instance
            .graphics_requirements::<xr::Vulkan>(self.system)
            .map_err(xr_call("xrGetVulkanGraphicsRequirements2KHR"))?;
        let want = xr::Version::new(1, 3, 0);
        if let Some(warning) = check_vulkan_version(
            want,
            reqs.min_api_version_supported,
            reqs.max_api_version_supported,
        )? {
            eprintln!("xr: warning: {warning}");
        }
        // SAFETY: the loader's vkGetInstanceProcAddr and a valid create-info (caller).
        let raw = unsafe {
            #[allow(clippy::missing_transmute_annotations)]
            let gipa = std::mem::transmute(entry.static_fn().get_instance_proc_addr);
            self.instance
                .create_vulkan_instance(self.system, gipa, info as *const _ as *const _)
                .map_err(xr_call("xrCreateVulkanInstanceKHR"))?
                .map_err(|code| XrError::Vulkan {
                    call: "vkCreateInstance",
                    code,
                })?
        };
        Ok(vk::Instance::from_raw(raw as _))
    }

    unsafe fn physical_device(
        &self,
        instance: &ash::Instance,
    ) -> Result<vk::PhysicalDevice, XrError> {
        // SAFETY: the instance was created through this runtime (caller).
        let raw = unsafe {
            self.instance
                .vulkan_graphics_device(self.system, instance.handle().as_raw() as _)
                .map_err(xr_call("xrGetVulkanGraphicsDevice2KHR"))?
        };
        Ok(vk::PhysicalDevice::from_raw(raw as _))
    }

    unsafe fn create_device(
        &self,
        entry: &ash::Entry,
        _instance: &ash::Instance,
        phd: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo<'_>,
    ) -> Result<vk::Device, XrError> {
        // SAFETY: as `create_instance`; `phd` is the runtime's device (caller).
        let raw = unsafe {
            #[allow(clippy::missing_transmute_annotations)]
            let gipa = std::mem::transmute(entry.static_fn().get_instance_proc_addr);
            self.instance
                .create_vulkan_device(
                    self.system,
                    gipa,
                    phd.as_raw() as _,
                    info as *const _ as *const _,
                )
                .map_err(xr_call("xrCreateVulkanDeviceKHR"))?
                .map_err(|code| XrError::Vulkan {
                    call: "vkCreateDevice",
                    code,
                })?
        };
        Ok(vk::Device::from_raw(raw as _))
    }
}

/// Vulkan created directly on the first physical device, no runtime involved.
pub struct DirectVulkan;

impl VulkanCreator for DirectVulkan {
    unsafe fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo<'_>,
    ) -> Result<vk::Instance, XrError> {
        // SAFETY: valid create-info (caller).
        unsafe { entry.create_instance(info, None) }
            .map(|i| i.handle())
            .map_err(|e| XrError::Vulkan {
                call: "vkCreateInstance",
                code: e.as_raw(),
            })
    }

    unsafe fn physical_device(
        &self,
        instance: &ash::Instance,
    ) -> Result<vk::PhysicalDevice, XrError> {
        // SAFETY: a live instance (caller).
        unsafe { instance.enumerate_physical_devices() }
            .map_err(|e| XrError::Vulkan {
                call: "vkEnumeratePhysicalDevices",
                code: e.as_raw(),
            })?
            .first()
            .copied()
            .ok_or_else(|| XrError::Gpu("no Vulkan physical device".into()))
    }

    unsafe fn create_device(
        &self,
        _entry: &ash::Entry,
        instance: &ash::Instance,
        phd: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo<'_>,
    ) -> Result<vk::Device, XrError> {
        // SAFETY: `phd` from `instance`, valid create-info (caller).
        unsafe { instance.create_device(phd, info, None) }
            .map(|d| d.handle())
            .map_err(|e| XrError::Vulkan {
                call: "vkCreateDevice",
                code: e.as_raw(),
            })
    }
}

/// wgpu on the created Vulkan device, and the raw handles `xrCreateSession` needs.
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

fn gpu_err(what: &'static str) -> impl Fn(String) -> XrError {
    move |e| XrError::Gpu(format!("{what}: {e}"))
}

/// Create Vulkan with `creator` and open wgpu on it. wgpu-hal owns and destroys the
/// instance and device when the last wgpu object goes.
pub fn create_gpu(creator: &impl VulkanCreator) -> Result<XrGpu, XrError> {
    // SAFETY: loads the system Vulkan loader; every handle below is created from it, in
    // the order and with the extensions and features wgpu-hal asks for, and handed to
    // wgpu-hal, which takes ownership (no drop callbacks).
    unsafe {
        let entry = ash::Entry::load().map_err(|e| gpu_err("loading libvulkan")(e.to_string()))?;
        let flags = wgpu::InstanceFlags::empty();
        let loader_version = instance_version(&entry)
            .map_err(|e| gpu_err("vkEnumerateInstanceVersion")(e.to_string()))?;
        if loader_version < vk::API_VERSION_1_1 {
            return Err(XrError::Gpu("the Vulkan loader is older than 1.1".into()));
        }
        let extensions = hal_vk::Instance::desired_extensions(&entry, loader_version, flags)
            .map_err(|e| gpu_err("Vulkan instance extensions")(e.to_string()))?;
        let ext_ptrs: Vec<*const c_char> = extensions.iter().map(|e| e.as_ptr()).collect();
        let app = application_info(VK_VERSION);
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_extension_names(&ext_ptrs);
        let raw_instance = creator.create_instance(&entry, &info)?;
        let ash_instance = ash::Instance::load(entry.static_fn(), raw_instance);
        let phd = creator.physical_device(&ash_instance)?;
        let hal_instance = hal_vk::Instance::from_raw(
            entry.clone(),
            ash_instance.clone(),
            loader_version.min(VK_VERSION),
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
        // wgpu-hal's own device creation uses queue family 0; so does this. It must draw.
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
        let raw_device = creator.create_device(&entry, &ash_instance, phd, &dev_info)?;
        let ash_device = ash::Device::load(ash_instance.fp_v1_0(), raw_device);
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
            device: RenderDevice(OpenedDevice {
                adapter,
                device,
                queue,
                info,
                timestamps: features.contains(wgpu::Features::TIMESTAMP_QUERY),
                limits,
            }),
            vk_instance: raw_instance.as_raw(),
            vk_physical_device: phd.as_raw(),
            vk_device: raw_device.as_raw(),
            queue_family,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vulkan_below_the_minimum_fails_and_above_the_tested_maximum_warns() {
        let v = xr::Version::new;
        let want = v(1, 3, 0);
        // Monado: 1.0.0 to 1023.1023.1023.
        assert_eq!(
            check_vulkan_version(want, v(1, 0, 0), v(1023, 1023, 1023)).unwrap(),
            None
        );
        assert_eq!(
            check_vulkan_version(want, v(1, 0, 0), v(1, 3, 0)).unwrap(),
            None
        );
        // Same major, lower minor: the old check let this pass silently.
        let w = check_vulkan_version(want, v(1, 0, 0), v(1, 1, 0))
            .unwrap()
            .expect("a warning");
        assert!(
            w.contains("up to 1.1.0") && w.contains("asks for Vulkan 1.3.0"),
            "{w}"
        );
        let e = check_vulkan_version(want, v(1, 4, 0), v(2, 0, 0)).unwrap_err();
        assert!(e.to_string().contains("needs Vulkan 1.4.0 or newer"), "{e}");
    }
}
