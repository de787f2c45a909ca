//! Opening a wgpu device for compute: any adapter (a discrete GPU, or Mesa lavapipe in CI).

use super::device::{DeviceRequest, OpenError, OpenedDevice, describe_adapter, open_device};

/// The compute solver's own device.
const COMPUTE: DeviceRequest = DeviceRequest {
    label: "incise compute",
    needed_by: "the stress kernel",
    textures: false,
};

/// Why no GPU device could be opened or used.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter: no GPU, no Vulkan/Metal/DX12/GL driver (on Debian, install
    /// `mesa-vulkan-drivers libvulkan1` for the lavapipe software adapter).
    #[error(
        "no GPU adapter found ({0}); install a GPU driver, or mesa-vulkan-drivers and libvulkan1 for the lavapipe software adapter, or use --device cpu"
    )]
    NoAdapter(String),
    /// The adapter refused the device.
    #[error("the GPU adapter {adapter} refused a compute device: {msg}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// Cause.
        msg: String,
    },
    /// The mesh is larger than the adapter's buffer limits.
    #[error("the mesh needs a {needed}-byte buffer but {adapter} allows {limit} bytes per binding")]
    TooLarge {
        /// Adapter name.
        adapter: String,
        /// Bytes needed.
        needed: u64,
        /// Bytes allowed.
        limit: u64,
    },
    /// The implicit scheme's coarse level could not be built.
    #[error(transparent)]
    Coarse(#[from] crate::implicit::CoarseError),
    /// The implicit scheme asks for a smoother the device does not have.
    #[error(
        "solver.scheme smoother {0} runs on the CPU only (the GPU smooths with block Jacobi): use --device cpu, or smoother: Jacobi"
    )]
    CpuOnlySmoother(&'static str),
    /// The implicit scheme's coarse level is too fine for its dense inverse on the device.
    #[error(
        "the implicit scheme's coarse level has {nodes} nodes; the GPU applies its inverse as a dense matrix and takes at most {max}: set a larger solver.scheme coarse_cell, or use --device cpu"
    )]
    CoarseTooLarge {
        /// Coarse nodes of the scene.
        nodes: usize,
        /// Most the device takes.
        max: usize,
    },
    /// Reading results back failed (device lost, out of memory).
    #[error("GPU readback failed: {0}")]
    Readback(String),
}

/// A device and queue for the compute solver, with what the adapter is.
#[derive(Debug, Clone)]
pub struct GpuContext {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, backend, device type.
    pub info: wgpu::AdapterInfo,
    /// Whether GPU timestamps can be taken inside compute passes.
    pub timestamps: bool,
    /// Largest storage buffer binding, bytes.
    pub max_binding: u64,
    /// The first device loss or uncaptured device error, if one happened.
    pub fault: DeviceFault,
}

/// Where a device reports that it was lost or hit an error nobody captured (instead of
/// wgpu's default, a panic): the solver checks it every frame and stops with
/// `SolverError::Device`, which the app answers by going on with the CPU solver.
#[derive(Debug, Clone, Default)]
pub struct DeviceFault(std::sync::Arc<std::sync::Mutex<Option<String>>>);

impl From<OpenError> for GpuError {
    fn from(e: OpenError) -> Self {
        match e {
            OpenError::NoAdapter(why) => GpuError::NoAdapter(why),
            OpenError::Refused { adapter, msg } => GpuError::Device { adapter, msg },
        }
    }
}

impl DeviceFault {
    /// Record `msg` unless a fault is already recorded.
    pub fn record(&self, msg: String) {
        if let Ok(mut slot) = self.0.lock() {
            slot.get_or_insert(msg);
        }
    }

    /// The recorded fault, if any.
    pub fn get(&self) -> Option<String> {
        self.0.lock().ok().and_then(|s| s.clone())
    }

    /// Route `device`'s loss and uncaptured errors here.
    pub fn watch(&self, device: &wgpu::Device) {
        let lost = self.clone();
        device.set_device_lost_callback(move |reason, msg| {
            lost.record(format!("device lost ({reason:?}): {msg}"));
        });
        let errors = self.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            errors.record(format!("device error: {e}"));
        }));
    }
}

impl GpuContext {
    /// Open the first high-performance adapter of any backend (env `WGPU_BACKEND` and
    /// friends are honoured), with the limits the solver needs.
    pub fn new() -> Result<Self, GpuError> {
        pollster::block_on(Self::open())
    }

    async fn open() -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let opened = open_device(&instance, None, &COMPUTE).await?;
        Ok(Self::on(&opened))
    }

    /// A context on `opened`'s device and queue (the same ones: wgpu handles are shared,
    /// not copied), whose loss and uncaptured errors go to the new fault record from now on.
    pub fn on(opened: &OpenedDevice) -> Self {
        let fault = DeviceFault::default();
        fault.watch(&opened.device);
        GpuContext {
            fault,
            device: opened.device.clone(),
            queue: opened.queue.clone(),
            info: opened.info.clone(),
            timestamps: opened.timestamps,
            max_binding: opened.limits.max_storage_buffer_binding_size,
        }
    }

    /// "name (backend, device type)" for reports.
    pub fn describe(&self) -> String {
        describe_adapter(&self.info)
    }
}
