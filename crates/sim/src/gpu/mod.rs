//! The tet solver on the GPU (wgpu compute, kernels in `gpu/shaders/`): prediction, coloured
//! Neo-Hookean projection, velocity update, stress and release run on the device with no
//! per-substep readback; under `scheme: Newton` the implicit steps run there too
//! (`gpu/newton/`, a readback per Newton evaluation, none per conjugate-gradient iteration). The CPU solver is the reference it must match; it also serves as
//! the host mirror (mesh, cut state, guards, statistics), so those exist once.

mod context;
mod device;
mod kernels;
mod layout;
mod newton;
mod readback;
mod solver;

pub use context::{DeviceFault, GpuContext, GpuError};
pub use device::{
    DeviceRequest, OpenError, OpenedDevice, STORAGE_BUFFERS, describe_adapter, open_device,
};
pub use kernels::{SHADER_STAGES, shader_source};
pub use newton::{MAX_COARSE_NODES, NEWTON_STAGES, newton_source};
pub use solver::{GpuSolver, GpuTiming};
