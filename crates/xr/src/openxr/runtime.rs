//! Finding the OpenXR runtime: open the loader, check the runtime offers Vulkan
//! rendering (`XR_KHR_vulkan_enable2`), create the instance and find the headset.

use ::openxr as xr;

use super::backdrop::Backdrop;
use super::error::{XrError, xr_call};
use super::manifest::ActiveRuntime;

/// An OpenXR instance on a runtime with a head-mounted display.
pub struct Runtime {
    /// The instance (with `XR_KHR_vulkan_enable2`).
    pub instance: xr::Instance,
    /// The headset.
    pub system: xr::SystemId,
    /// "name version" of the runtime.
    pub name: String,
    /// What the organ is seen against.
    pub backdrop: Backdrop,
    /// The environment blend mode submitted with each frame.
    pub blend_mode: xr::EnvironmentBlendMode,
}

/// Open the loader and the active runtime, and find a headset.
pub fn open_runtime() -> Result<Runtime, XrError> {
    // SAFETY: loading the system's OpenXR loader library runs its initialisers; it is
    // the Khronos loader (or a vendor's) and is loaded once.
    let entry =
        unsafe { xr::Entry::load(&()) }.map_err(|e| XrError::LoaderMissing(e.to_string()))?;
    let available = entry
        .enumerate_extensions()
        .map_err(|e| XrError::RuntimeUnavailable {
            detail: e.to_string(),
            manifest: ActiveRuntime::find(),
        })?;
    let app = xr::ApplicationInfo {
        application_name: "incise",
        application_version: 1,
        engine_name: "incise",
        engine_version: 1,
        api_version: xr::Version::new(1, 0, 0),
    };
    let mut wanted = xr::ExtensionSet::default();
    wanted.khr_vulkan_enable2 = available.khr_vulkan_enable2;
    wanted.fb_passthrough = available.fb_passthrough;
    let instance = entry
        .create_instance(&app, &wanted, &[], &())
        .map_err(|e| match e {
            // The extensions were listed, so the loader found and loaded the runtime: every
            // failure but "no runtime" is the runtime's own, named as such.
            xr::sys::Result::ERROR_RUNTIME_UNAVAILABLE => XrError::RuntimeUnavailable {
                detail: e.to_string(),
                manifest: ActiveRuntime::find(),
            },
            result => XrError::CreateInstance {
                result,
                manifest: ActiveRuntime::find(),
            },
        })?;
    let props = instance
        .properties()
        .map_err(xr_call("xrGetInstanceProperties"))?;
    let name = format!("{} {}", props.runtime_name, props.runtime_version);
    if !available.khr_vulkan_enable2 {
        return Err(XrError::NoVulkan { runtime: name });
    }
    let system = instance
        .system(xr::FormFactor::HEAD_MOUNTED_DISPLAY)
        .map_err(|e| XrError::NoHeadset {
            runtime: name.clone(),
            detail: e.to_string(),
        })?;
    let modes = instance
        .enumerate_environment_blend_modes(system, xr::ViewConfigurationType::PRIMARY_STEREO)
        .map_err(xr_call("xrEnumerateEnvironmentBlendModes"))?;
    let backdrop = Backdrop::choose(
        available.fb_passthrough,
        modes.contains(&xr::EnvironmentBlendMode::ALPHA_BLEND),
    );
    let blend_mode = match backdrop {
        Backdrop::AlphaBlend => xr::EnvironmentBlendMode::ALPHA_BLEND,
        _ if modes.contains(&xr::EnvironmentBlendMode::OPAQUE) => xr::EnvironmentBlendMode::OPAQUE,
        _ => modes
            .first()
            .copied()
            .unwrap_or(xr::EnvironmentBlendMode::OPAQUE),
    };
    Ok(Runtime {
        instance,
        system,
        name,
        backdrop,
        blend_mode,
    })
}
