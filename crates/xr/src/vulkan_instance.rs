//! Vulkan instances without the window-system extensions a run does not use: none for
//! offscreen work ([`instance`]), no Wayland for a window on X11 ([`x11_instance`]). With
//! `VK_KHR_wayland_surface` enabled, Mesa's device-select layer connects to a Wayland
//! display to rank GPUs and, where there is none (no `XDG_RUNTIME_DIR`: Xvfb, ssh, CI),
//! prints "error: XDG_RUNTIME_DIR is invalid or not set" on every run. wgpu-hal enables
//! every WSI extension the loader offers and has no switch for it, so the instance is
//! made here and handed to wgpu-hal, which owns it from then on.

use std::ffi::{CStr, c_char};

use ash::vk;
use wgpu::hal::vulkan as hal_vk;

/// Instance extensions only a window needs.
const WINDOW_SYSTEM: [&CStr; 10] = [
    ash::khr::surface::NAME,
    ash::khr::xlib_surface::NAME,
    ash::khr::xcb_surface::NAME,
    ash::khr::wayland_surface::NAME,
    ash::khr::display::NAME,
    ash::khr::get_display_properties2::NAME,
    ash::ext::acquire_drm_display::NAME,
    ash::ext::direct_mode_display::NAME,
    ash::ext::swapchain_colorspace::NAME,
    ash::khr::android_surface::NAME,
];

/// A wgpu instance on a window-less Vulkan instance, or `None` where Vulkan (≥ 1.1) is
/// not there or refuses (the caller then opens wgpu's own instance).
pub fn instance() -> Option<wgpu::Instance> {
    instance_without(&WINDOW_SYSTEM)
}

/// A wgpu instance on a Vulkan instance that can draw into X11 windows but has no
/// Wayland surface extension, or `None` as for [`instance`].
pub fn x11_instance() -> Option<wgpu::Instance> {
    instance_without(&[ash::khr::wayland_surface::NAME])
}

/// A wgpu instance on a Vulkan instance with every extension wgpu-hal wants but `left_out`.
fn instance_without(left_out: &[&CStr]) -> Option<wgpu::Instance> {
    // SAFETY: the system Vulkan loader is loaded and the instance created from it with
    // the extensions listed; wgpu-hal is given exactly that list (it checks it before any
    // surface use) and takes ownership of the instance (no drop callback).
    unsafe {
        let entry = ash::Entry::load().ok()?;
        let version = instance_version(&entry).ok()?;
        if version < vk::API_VERSION_1_1 {
            return None;
        }
        let version = version.min(vk::API_VERSION_1_3);
        let flags = wgpu::InstanceFlags::empty();
        let mut extensions = hal_vk::Instance::desired_extensions(&entry, version, flags).ok()?;
        extensions.retain(|e| !left_out.contains(e));
        let names: Vec<*const c_char> = extensions.iter().map(|e| e.as_ptr()).collect();
        let app = application_info(version);
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_extension_names(&names);
        let raw = entry.create_instance(&info, None).ok()?;
        let hal = hal_vk::Instance::from_raw(
            entry,
            raw.clone(),
            version,
            0,
            None,
            extensions,
            flags,
            wgpu::MemoryBudgetThresholds::default(),
            false,
            None,
        );
        let Ok(hal) = hal else {
            raw.destroy_instance(None);
            return None;
        };
        Some(wgpu::Instance::from_hal::<wgpu::hal::api::Vulkan>(hal))
    }
}

/// The Vulkan loader's instance version as "major.minor.patch", or `None` where no Vulkan
/// loader can be loaded (`incise doctor`).
pub fn loader_version() -> Option<String> {
    // SAFETY: loading the system Vulkan loader; only its version is queried.
    let entry = unsafe { ash::Entry::load() }.ok()?;
    let v = instance_version(&entry).ok()?;
    Some(format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    ))
}

/// The instance version `entry`'s loader offers (1.0 for a loader older than the query).
pub fn instance_version(entry: &ash::Entry) -> Result<u32, vk::Result> {
    // SAFETY: a plain query of a loaded entry.
    Ok(unsafe { entry.try_enumerate_instance_version() }?.unwrap_or(vk::API_VERSION_1_0))
}

/// incise's application info for a Vulkan instance of API `version`.
pub fn application_info(version: u32) -> vk::ApplicationInfo<'static> {
    vk::ApplicationInfo::default()
        .application_name(c"incise")
        .engine_name(c"incise")
        .api_version(version)
}
