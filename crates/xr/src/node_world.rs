//! World positions of the nodes on the device, from the GPU solver's displacements: a
//! compute pass writes `x = X + u` (`node_world.wgsl`) into the renderer's node buffer, so
//! the render shaders read the same world positions as when the host uploads them.

use incise_sim::TetMesh;
use wgpu::util::DeviceExt;

use crate::shaders;

const WG: u32 = 64;

/// The rest positions on the device and the pipeline that adds displacements to them.
pub(crate) struct NodeWorld {
    rest: wgpu::Buffer,
    node_count: u32,
    max_groups: u32,
    pipeline: wgpu::ComputePipeline,
}

impl NodeWorld {
    /// Upload `mesh`'s rest positions (`vec4<f32>` per node).
    pub fn new(device: &wgpu::Device, mesh: &TetMesh) -> Self {
        let mut rest: Vec<[f32; 4]> = mesh
            .rest_positions
            .iter()
            .map(|p| [p.x, p.y, p.z, 1.0])
            .collect();
        // Two elements at least (32 bytes), so a bindable buffer; the shader's length check
        // reads `rest`, so padding never writes past the node buffer (also ≥ 32 bytes).
        let node_count = rest.len() as u32;
        rest.resize(rest.len().max(2), [0.0; 4]);
        let rest = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rest positions"),
            contents: bytemuck::cast_slice(&rest),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("node_world"),
            layout: None,
            module: &shaders::module(device, "node_world"),
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        NodeWorld {
            rest,
            node_count,
            max_groups: device.limits().max_compute_workgroups_per_dimension.max(1),
            pipeline,
        }
    }

    /// Record `world = rest + displacement` (xyz; w = 1) into `encoder`.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        displacement: &wgpu::Buffer,
        world: &wgpu::Buffer,
    ) {
        if self.node_count == 0 {
            return;
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("node world"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.rest.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: displacement.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: world.as_entire_binding(),
                },
            ],
        });
        let groups = self.node_count.div_ceil(WG);
        let x = groups.min(self.max_groups);
        let y = groups.div_ceil(x);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("node world"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }
}
