//! Opening one wgpu device that both renders and runs the GPU solver, so the renderer can
//! read the solver's node positions without a round trip through the host.

use incise_sim::gpu::{
    DeviceRequest, GpuContext, OpenError, OpenedDevice, describe_adapter, open_device,
};

use crate::error::RenderError;

/// One device for rendering and the solver: the adapter's texture limits too.
const RENDER: DeviceRequest = DeviceRequest {
    label: "incise",
    needed_by: "incise",
    textures: true,
};

/// An adapter's device and queue, opened for rendering and compute; its fields
/// (adapter, device, queue, info, timestamps, limits) are the [`OpenedDevice`]'s.
#[derive(Debug, Clone)]
pub struct RenderDevice(
    /// The device as opened, by [`open_device`] or on the headset's Vulkan device.
    pub OpenedDevice,
);

impl std::ops::Deref for RenderDevice {
    type Target = OpenedDevice;

    fn deref(&self) -> &OpenedDevice {
        &self.0
    }
}

impl RenderDevice {
    /// A second device, with its own queue, on the best adapter of wgpu's standard
    /// instance (primary backends; honours `WGPU_BACKEND`): for compute that must not
    /// share a queue with the headset's device. Not the window-less instance of
    /// [`RenderDevice::headless`]: wgpu-hal enables the swapchain device extension
    /// there without the instance's surface extension, which the Vulkan validation
    /// layer reports as an error.
    pub fn separate() -> Result<Self, RenderError> {
        let primary = wgpu::InstanceDescriptor {
            backends: wgpu::Backends::PRIMARY,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        }
        .with_env();
        pollster::block_on(Self::open(&wgpu::Instance::new(primary), None))
    }

    /// Open a device without a window (offscreen rendering, benchmarks, tests). Honours
    /// `WGPU_BACKEND` and friends. Without it, Vulkan is opened without the window-system
    /// extensions first ([`crate::vulkan_instance`]), then the other primary backends
    /// (Metal, DX12), then every backend built in (GL too in a build with the app's `gl`
    /// feature): asking for Wayland/X11 surfaces (Mesa's device-select layer then connects
    /// to the display) or starting GL (it probes the window systems) prints "error:
    /// XDG_RUNTIME_DIR is invalid or not set" on a machine with no display.
    pub fn headless() -> Result<Self, RenderError> {
        let from_env = std::env::var_os("WGPU_BACKEND").is_some();
        if !from_env
            && let Some(vulkan) = crate::vulkan_instance::instance()
            && let Ok(dev) = pollster::block_on(Self::open(&vulkan, None))
        {
            return Ok(dev);
        }
        let primary = wgpu::InstanceDescriptor {
            backends: wgpu::Backends::PRIMARY,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        }
        .with_env();
        match pollster::block_on(Self::open(&wgpu::Instance::new(primary), None)) {
            Err(RenderError::NoAdapter(_)) if !from_env => {
                let all = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
                pollster::block_on(Self::open(&wgpu::Instance::new(all), None))
            }
            opened => opened,
        }
    }

    /// Open a device on `instance` whose adapter can present to `surface`, if given.
    pub async fn open(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self, RenderError> {
        let opened = open_device(instance, surface, &RENDER)
            .await
            .map_err(|e| match e {
                OpenError::NoAdapter(why) => RenderError::NoAdapter(why),
                OpenError::Refused { adapter, msg } => RenderError::Device { adapter, msg },
            })?;
        Ok(RenderDevice(opened))
    }

    /// The same device as a [`GpuContext`] for the GPU solver (device loss and uncaptured
    /// errors are routed to the context's fault record from here on).
    pub fn compute_context(&self) -> GpuContext {
        GpuContext::on(&self.0)
    }

    /// "name (backend, device type)" for reports.
    pub fn describe(&self) -> String {
        describe_adapter(&self.info)
    }
}
