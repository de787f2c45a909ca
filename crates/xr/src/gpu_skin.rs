//! The skin deformed on the GPU every frame: a compute pass combines each skin vertex's
//! four tet nodes with its barycentric weights (`skin_deform.wgsl`), a second gathers
//! area-weighted normals from the vertex's triangles (`skin_normals.wgsl`).

use bytemuck::{Pod, Zeroable};
use incise_sim::skin::Skin;
use wgpu::util::DeviceExt;

use crate::shaders;

const WG: u32 = 64;

/// `Embedding` of skin_deform.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuEmbedding {
    nodes: [u32; 4],
    bary: [f32; 4],
}

/// Device buffers and pipelines of the skin.
pub(crate) struct GpuSkin {
    /// Deformed positions, `vec4<f32>` per skin vertex (vertex and storage buffer).
    pub positions: wgpu::Buffer,
    /// Unit normals, `vec4<f32>` per skin vertex.
    pub normals: wgpu::Buffer,
    vertex_count: u32,
    max_groups: u32,
    deform: wgpu::ComputePipeline,
    normal: wgpu::ComputePipeline,
    deform_group: wgpu::BindGroup,
    normal_group: wgpu::BindGroup,
}

/// A storage buffer holding `bytes` (at least 32 bytes, so empty lists stay bindable).
fn storage_init(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let mut contents = bytes.to_vec();
    contents.resize(bytes.len().max(32), 0);
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &contents,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

impl GpuSkin {
    /// Upload `skin`'s embedding and topology; node positions are read from `nodes`.
    pub fn new(device: &wgpu::Device, skin: &Skin, nodes: &wgpu::Buffer) -> Self {
        let n = skin.embedding.len();
        let embedding: Vec<GpuEmbedding> = skin
            .embedding
            .iter()
            .map(|e| GpuEmbedding {
                nodes: e.nodes,
                bary: e.bary,
            })
            .collect();
        let triangles: Vec<u32> = skin.surface.triangles.iter().flatten().copied().collect();
        // Vertex → triangle adjacency (CSR), so normals are gathered without atomics.
        let mut offsets = vec![0u32; n + 1];
        for tri in &skin.surface.triangles {
            for &v in tri {
                if (v as usize) < n {
                    offsets[v as usize + 1] += 1;
                }
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut adjacency = vec![0u32; offsets[n] as usize];
        for (t, tri) in skin.surface.triangles.iter().enumerate() {
            for &v in tri {
                if (v as usize) < n {
                    adjacency[fill[v as usize] as usize] = t as u32;
                    fill[v as usize] += 1;
                }
            }
        }
        // Triangles naming missing vertices would read out of range: point them at 0.
        let triangles: Vec<u32> = triangles
            .into_iter()
            .map(|v| if (v as usize) < n { v } else { 0 })
            .collect();
        let vertex_buffer = |label: &str| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (n as u64 * 16).max(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::VERTEX
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let positions = vertex_buffer("skin positions");
        let normals = vertex_buffer("skin normals");
        let embedding = storage_init(device, "skin embedding", bytemuck::cast_slice(&embedding));
        let triangles = storage_init(device, "skin triangles", bytemuck::cast_slice(&triangles));
        let offsets = storage_init(
            device,
            "skin adjacency offsets",
            bytemuck::cast_slice(&offsets),
        );
        let adjacency = storage_init(device, "skin adjacency", bytemuck::cast_slice(&adjacency));
        let pipeline = |name: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: None,
                module: &shaders::module(device, name),
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let deform = pipeline("skin_deform");
        let normal = pipeline("skin_normals");
        let group = |pipe: &wgpu::ComputePipeline, bufs: &[&wgpu::Buffer]| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipe.get_bind_group_layout(0),
                entries: &bufs
                    .iter()
                    .enumerate()
                    .map(|(i, b)| wgpu::BindGroupEntry {
                        binding: i as u32,
                        resource: b.as_entire_binding(),
                    })
                    .collect::<Vec<_>>(),
            })
        };
        let deform_group = group(&deform, &[nodes, &embedding, &positions]);
        let normal_group = group(
            &normal,
            &[&positions, &triangles, &offsets, &adjacency, &normals],
        );
        GpuSkin {
            positions,
            normals,
            vertex_count: n as u32,
            max_groups: device.limits().max_compute_workgroups_per_dimension.max(1),
            deform,
            normal,
            deform_group,
            normal_group,
        }
    }

    /// Number of skin vertices.
    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    /// Record both passes (deform, then normals) into `pass`.
    pub fn record(&self, pass: &mut wgpu::ComputePass<'_>) {
        if self.vertex_count == 0 {
            return;
        }
        let groups = self.vertex_count.div_ceil(WG);
        let x = groups.min(self.max_groups);
        let y = groups.div_ceil(x);
        pass.set_pipeline(&self.deform);
        pass.set_bind_group(0, &self.deform_group, &[]);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_pipeline(&self.normal);
        pass.set_bind_group(0, &self.normal_group, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }
}
