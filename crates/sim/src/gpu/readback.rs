//! Reading staging buffers back on the host: each one mapped, the device waited for once,
//! its contents copied out and the buffer unmapped.

use super::GpuError;

/// The contents of `bufs` (mappable staging buffers whose copies have been submitted), in
/// order, each as `T`s.
pub(crate) fn read_mapped<T: bytemuck::Pod>(
    device: &wgpu::Device,
    bufs: &[&wgpu::Buffer],
) -> Result<Vec<Vec<T>>, GpuError> {
    for b in bufs {
        b.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    }
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    bufs.iter()
        .map(|b| {
            let v = b
                .slice(..)
                .get_mapped_range()
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            let out = bytemuck::cast_slice(&v).to_vec();
            drop(v);
            b.unmap();
            Ok(out)
        })
        .collect()
}
