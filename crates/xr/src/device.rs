//! Opening one wgpu device that both renders and runs the GPU solver, so the renderer can
//! read the solver's node positions without a round trip through the host.

use incise_sim::gpu::GpuContext;

use crate::error::RenderError;

/// Storage buffers per stage the GPU solver's stress kernel needs (and more than the
/// renderer's five).
const STORAGE_BUFFERS: u32 = 8;

/// An adapter's device and queue, opened for rendering and compute.
#[derive(Debug, Clone)]
pub struct RenderDevice {
    /// The adapter (for surface capabilities).
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter is.
    pub info: wgpu::AdapterInfo,
    /// Whether GPU timestamps can be taken in passes.
    pub timestamps: bool,
    /// The adapter's limits as granted.
    pub limits: wgpu::Limits,
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
    /// extensions first ([`crate::headless_vulkan`]), then the other primary backends
    /// (Metal, DX12), then GL: asking for Wayland/X11 surfaces (Mesa's device-select layer
    /// then connects to the display) or starting GL (it probes the window systems) prints
    /// "error: XDG_RUNTIME_DIR is invalid or not set" on a machine with no display.
    pub fn headless() -> Result<Self, RenderError> {
        let from_env = std::env::var_os("WGPU_BACKEND").is_some();
        if !from_env
            && let Some(vulkan) = crate::headless_vulkan::instance()
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
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: surface,
                apply_limit_buckets: false,
            })
            .await
            .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let available = adapter.limits();
        if available.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS {
            return Err(RenderError::Device {
                adapter: info.name.clone(),
                msg: format!(
                    "it allows {} storage buffers per shader stage; incise needs {STORAGE_BUFFERS}",
                    available.max_storage_buffers_per_shader_stage
                ),
            });
        }
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let required_features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let required_limits = wgpu::Limits {
            max_storage_buffers_per_shader_stage: STORAGE_BUFFERS,
            max_storage_buffer_binding_size: available.max_storage_buffer_binding_size,
            max_buffer_size: available.max_buffer_size,
            max_compute_workgroups_per_dimension: available.max_compute_workgroups_per_dimension,
            max_texture_dimension_2d: available.max_texture_dimension_2d,
            max_texture_array_layers: available.max_texture_array_layers,
            ..wgpu::Limits::downlevel_defaults()
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("incise"),
                required_features,
                required_limits: required_limits.clone(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| RenderError::Device {
                adapter: info.name.clone(),
                msg: e.to_string(),
            })?;
        Ok(RenderDevice {
            adapter,
            device,
            queue,
            info,
            timestamps,
            limits: required_limits,
        })
    }

    /// The same device as a [`GpuContext`] for the GPU solver (device loss and uncaptured
    /// errors are routed to the context's fault record from here on).
    pub fn compute_context(&self) -> GpuContext {
        let fault = incise_sim::gpu::DeviceFault::default();
        fault.watch(&self.device);
        GpuContext {
            fault,
            device: self.device.clone(),
            queue: self.queue.clone(),
            info: self.info.clone(),
            timestamps: self.timestamps,
            max_binding: self.limits.max_storage_buffer_binding_size,
        }
    }

    /// "name (backend, device type)" for reports.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }
}
