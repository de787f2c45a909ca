//! Opening a wgpu device with the limits incise needs, once for both users: the compute
//! solver's own device ([`super::GpuContext`]) and the renderer's device, which the solver
//! shares (`incise_xr::RenderDevice`).

/// Storage buffers per shader stage the GPU solver's stress kernel needs (more than the
/// renderer's five).
pub const STORAGE_BUFFERS: u32 = 8;

/// What a caller asks of its device beyond the solver's limits.
#[derive(Debug, Clone, Copy)]
pub struct DeviceRequest {
    /// The device's label.
    pub label: &'static str,
    /// Who needs the storage buffers, for the refusal message ("the stress kernel").
    pub needed_by: &'static str,
    /// Whether the adapter's largest 2D texture size and layer count are asked for too.
    pub textures: bool,
}

/// A device and queue, with the adapter they came from and what was granted.
#[derive(Debug, Clone)]
pub struct OpenedDevice {
    /// The adapter (for surface capabilities).
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, backend, device type.
    pub info: wgpu::AdapterInfo,
    /// Whether GPU timestamps can be taken inside passes.
    pub timestamps: bool,
    /// The limits as granted.
    pub limits: wgpu::Limits,
}

/// Why no device was opened; each caller turns it into its own error, with its own advice.
#[derive(Debug, Clone)]
pub enum OpenError {
    /// The instance offered no adapter (wgpu's reason).
    NoAdapter(String),
    /// The adapter has too few storage buffers per stage, or refused the device.
    Refused {
        /// Adapter name.
        adapter: String,
        /// Cause.
        msg: String,
    },
}

/// Open a device on the first high-performance adapter of `instance` that can present to
/// `surface`, if given: any adapter, a software one (Mesa's lavapipe) included, but never
/// a forced fallback. Timestamps are asked for where the adapter has them; the buffer and
/// workgroup limits (and, with `request.textures`, the texture limits) are the adapter's
/// own, the rest wgpu's downlevel defaults.
pub async fn open_device(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface<'_>>,
    request: &DeviceRequest,
) -> Result<OpenedDevice, OpenError> {
    let adapter = instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: surface,
            apply_limit_buckets: false,
        })
        .await
        .map_err(|e| OpenError::NoAdapter(e.to_string()))?;
    let info = adapter.get_info();
    let available = adapter.limits();
    if available.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS {
        return Err(OpenError::Refused {
            adapter: info.name.clone(),
            msg: format!(
                "it allows {} storage buffers per shader stage; {} needs {STORAGE_BUFFERS}",
                available.max_storage_buffers_per_shader_stage, request.needed_by
            ),
        });
    }
    let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    let required_features = if timestamps {
        wgpu::Features::TIMESTAMP_QUERY
    } else {
        wgpu::Features::empty()
    };
    let defaults = wgpu::Limits::downlevel_defaults();
    let (max_texture_dimension_2d, max_texture_array_layers) = if request.textures {
        (
            available.max_texture_dimension_2d,
            available.max_texture_array_layers,
        )
    } else {
        (
            defaults.max_texture_dimension_2d,
            defaults.max_texture_array_layers,
        )
    };
    let limits = wgpu::Limits {
        max_storage_buffers_per_shader_stage: STORAGE_BUFFERS,
        max_storage_buffer_binding_size: available.max_storage_buffer_binding_size,
        max_buffer_size: available.max_buffer_size,
        max_compute_workgroups_per_dimension: available.max_compute_workgroups_per_dimension,
        max_texture_dimension_2d,
        max_texture_array_layers,
        ..defaults
    };
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some(request.label),
            required_features,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        })
        .await
        .map_err(|e| OpenError::Refused {
            adapter: info.name.clone(),
            msg: e.to_string(),
        })?;
    Ok(OpenedDevice {
        adapter,
        device,
        queue,
        info,
        timestamps,
        limits,
    })
}

/// "name (backend, device type)" of an adapter, for reports.
pub fn describe_adapter(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
}
