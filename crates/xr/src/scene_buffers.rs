//! Device copies of what changes with the body: node positions, stress, the visible skin
//! triangles, cut and surface faces, wireframe edges, marker instances and surface-line
//! ribbons, with the bind group the render pipelines share. Lists that depend on the cut
//! are rebuilt only when tets were released since the last frame; markers and ribbons
//! are rebuilt every frame.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use incise_sim::TetMesh;
use incise_sim::mesh::{NO_NEIGHBOR, TET_EDGES, TET_FACES};
use incise_sim::skin::Skin;

use crate::frame::{BodyState, RenderSettings};
use crate::node_world::NodeWorld;
use crate::ribbon::{self, LineVertex};

/// Bytes between the per-view globals (the uniform-offset alignment every adapter accepts).
pub(crate) const GLOBALS_STRIDE: u64 = 256;
/// Views (eyes) one frame can render.
pub(crate) const MAX_VIEWS: u64 = 4;

/// `Globals` of render_common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct Globals {
    pub view_proj: [[f32; 4]; 4],
    pub tool_model: [[f32; 4]; 4],
    pub panel_model: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub light: [f32; 4],
    pub misc: [f32; 4],
}

/// One marker sphere instance: centre and radius, colour.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct Marker {
    pub centre_radius: [f32; 4],
    pub colour: [f32; 4],
}

/// A buffer that is reallocated (doubling) when a list outgrows it.
pub(crate) struct GrowBuffer {
    pub buffer: wgpu::Buffer,
    label: &'static str,
    usage: wgpu::BufferUsages,
    /// Elements written by the last [`GrowBuffer::write`].
    pub len: u32,
}

impl GrowBuffer {
    fn new(
        device: &wgpu::Device,
        label: &'static str,
        usage: wgpu::BufferUsages,
        bytes: u64,
    ) -> Self {
        GrowBuffer {
            buffer: create(device, label, usage | wgpu::BufferUsages::COPY_DST, bytes),
            label,
            usage,
            len: 0,
        }
    }

    /// Write `items`; returns true when the buffer had to be reallocated.
    fn write<T: Pod>(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, items: &[T]) -> bool {
        let bytes: &[u8] = bytemuck::cast_slice(items);
        let grown = bytes.len() as u64 > self.buffer.size();
        if grown {
            let size = (bytes.len() as u64).next_power_of_two();
            self.buffer = create(
                device,
                self.label,
                self.usage | wgpu::BufferUsages::COPY_DST,
                size,
            );
        }
        if !bytes.is_empty() {
            queue.write_buffer(&self.buffer, 0, bytes);
        }
        self.len = items.len() as u32;
        grown
    }
}

fn create(
    device: &wgpu::Device,
    label: &str,
    usage: wgpu::BufferUsages,
    bytes: u64,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        // Multiple of 16 and at least 32 bytes: every binding stays valid when empty.
        size: bytes.max(32).next_multiple_of(16),
        usage,
        mapped_at_creation: false,
    })
}

/// The per-body device data.
pub(crate) struct SceneBuffers {
    pub globals: wgpu::Buffer,
    pub nodes: wgpu::Buffer,
    pub von_mises: wgpu::Buffer,
    pub cut_faces: GrowBuffer,
    pub surface_faces: GrowBuffer,
    pub edges: GrowBuffer,
    pub skin_index: GrowBuffer,
    pub markers: GrowBuffer,
    /// Surface-line ribbon vertices (a triangle list).
    pub lines: GrowBuffer,
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    tets: Vec<[u32; 4]>,
    face_neighbors: Vec<[u32; 4]>,
    skin_tet: Vec<u32>,
    skin_triangles: Vec<[u32; 3]>,
    node_count: usize,
    /// Radius of a pinned-node marker, m.
    pub pin_radius: f32,
    /// Released-tet count the face lists and skin indices were built for.
    faces_built_for: Option<usize>,
    /// Released-tet count the wireframe edges were built for.
    edges_built_for: Option<usize>,
    /// Adds the rest positions to device displacements.
    node_world: NodeWorld,
    host_nodes: Vec<[f32; 4]>,
    host_lines: Vec<LineVertex>,
}

impl SceneBuffers {
    pub fn new(device: &wgpu::Device, mesh: &TetMesh, skin: &Skin) -> Self {
        use wgpu::BufferUsages as U;
        let storage = U::STORAGE | U::COPY_DST;
        let globals = create(
            device,
            "globals",
            U::UNIFORM | U::COPY_DST,
            GLOBALS_STRIDE * MAX_VIEWS,
        );
        let nodes = create(device, "nodes", storage, mesh.node_count() as u64 * 16);
        let von_mises = create(device, "von mises", storage, mesh.tet_count() as u64 * 4);
        let faces = mesh.boundary.len() as u64 * 16;
        let cut_faces = GrowBuffer::new(device, "cut faces", U::STORAGE, faces / 8);
        let surface_faces = GrowBuffer::new(device, "surface faces", U::STORAGE, faces);
        let edges = GrowBuffer::new(device, "edges", U::STORAGE, 32);
        let skin_index = GrowBuffer::new(
            device,
            "skin indices",
            U::INDEX,
            skin.surface.triangles.len() as u64 * 12,
        );
        let markers = GrowBuffer::new(device, "markers", U::VERTEX, 64 * 32);
        let lines = GrowBuffer::new(device, "surface lines", U::VERTEX, 0);
        let entry = |binding: u32, ty: wgpu::BindingType, vis: wgpu::ShaderStages| {
            wgpu::BindGroupLayoutEntry {
                binding,
                visibility: vis,
                ty,
                count: None,
            }
        };
        let read_only = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let vs = wgpu::ShaderStages::VERTEX;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(
                            std::mem::size_of::<Globals>() as u64
                        ),
                    },
                    wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ),
                entry(1, read_only, vs),
                entry(2, read_only, vs),
                entry(3, read_only, vs),
                entry(4, read_only, vs),
                entry(5, read_only, vs),
            ],
        });
        let bind_group = Self::bind(
            device,
            &layout,
            &globals,
            &nodes,
            &von_mises,
            [&cut_faces.buffer, &surface_faces.buffer, &edges.buffer],
        );
        let edge_sum: f32 = mesh
            .tets
            .iter()
            .take(2000)
            .flat_map(|t| {
                TET_EDGES.iter().map(move |&(a, b)| {
                    (mesh.rest_positions[t[a] as usize] - mesh.rest_positions[t[b] as usize])
                        .length()
                })
            })
            .sum();
        let edge_count = (mesh.tet_count().min(2000) * 6).max(1) as f32;
        SceneBuffers {
            globals,
            nodes,
            von_mises,
            cut_faces,
            surface_faces,
            edges,
            skin_index,
            markers,
            lines,
            layout,
            bind_group,
            tets: mesh.tets.clone(),
            face_neighbors: mesh.face_neighbors.clone(),
            skin_tet: skin.embedding.iter().map(|e| e.tet).collect(),
            skin_triangles: skin.surface.triangles.clone(),
            node_count: mesh.node_count(),
            pin_radius: 0.3 * edge_sum / edge_count,
            faces_built_for: None,
            edges_built_for: None,
            node_world: NodeWorld::new(device, mesh),
            host_nodes: Vec::new(),
            host_lines: Vec::new(),
        }
    }

    fn bind(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        globals: &wgpu::Buffer,
        nodes: &wgpu::Buffer,
        von_mises: &wgpu::Buffer,
        lists: [&wgpu::Buffer; 3],
    ) -> wgpu::BindGroup {
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: globals,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<Globals>() as u64),
                }),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: nodes.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: von_mises.as_entire_binding(),
            },
        ];
        for (i, b) in lists.into_iter().enumerate() {
            entries.push(wgpu::BindGroupEntry {
                binding: 3 + i as u32,
                resource: b.as_entire_binding(),
            });
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout,
            entries: &entries,
        })
    }

    /// Bring the device copies up to date with `state`; node world positions from device
    /// displacements are computed by a pass recorded into `encoder`.
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        state: &BodyState<'_>,
        settings: &RenderSettings,
    ) {
        let n = self.node_count.min(state.positions.len());
        match state.device_displacements {
            Some(src) if src.size() >= self.node_count as u64 * 16 => {
                self.node_world.record(device, encoder, src, &self.nodes);
            }
            _ => {
                self.host_nodes.clear();
                self.host_nodes
                    .extend(state.positions[..n].iter().map(|p| [p.x, p.y, p.z, 1.0]));
                queue.write_buffer(&self.nodes, 0, bytemuck::cast_slice(&self.host_nodes));
            }
        }
        if settings.overlays.stress {
            let t = self.tets.len().min(state.heat.len());
            queue.write_buffer(&self.von_mises, 0, bytemuck::cast_slice(&state.heat[..t]));
        }
        let released = state.cut.released_count();
        let mut grown = false;
        if self.faces_built_for != Some(released) {
            grown |= self.rebuild_faces(device, queue, state);
            self.faces_built_for = Some(released);
        }
        if settings.overlays.wireframe && self.edges_built_for != Some(released) {
            grown |= self.rebuild_edges(device, queue, state);
            self.edges_built_for = Some(released);
        }
        self.update_markers(device, queue, state, settings);
        self.host_lines.clear();
        ribbon::build(&settings.lines, &mut self.host_lines);
        self.lines.write(device, queue, &self.host_lines);
        if grown {
            self.bind_group = Self::bind(
                device,
                &self.layout,
                &self.globals,
                &self.nodes,
                &self.von_mises,
                [
                    &self.cut_faces.buffer,
                    &self.surface_faces.buffer,
                    &self.edges.buffer,
                ],
            );
        }
    }

    /// Visible faces (all, and the cut ones) and the skin triangles of live tets.
    fn rebuild_faces(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        state: &BodyState<'_>,
    ) -> bool {
        let live = state.cut.live();
        let is_live = |t: u32| live.get(t as usize).copied().unwrap_or(true);
        let mut surface = Vec::with_capacity(state.cut.visible_faces().len());
        let mut cut = Vec::new();
        for &(t, f) in state.cut.visible_faces() {
            let Some(tet) = self.tets.get(t as usize) else {
                continue;
            };
            let [a, b, c] = TET_FACES[f as usize].map(|l| tet[l]);
            let face = [a, b, c, t];
            surface.push(face);
            if self.face_neighbors[t as usize][f as usize] != NO_NEIGHBOR {
                cut.push(face);
            }
        }
        let indices: Vec<[u32; 3]> = self
            .skin_triangles
            .iter()
            .copied()
            .filter(|tri| {
                tri.iter()
                    .all(|&v| self.skin_tet.get(v as usize).is_some_and(|&t| is_live(t)))
            })
            .collect();
        self.skin_index.write(device, queue, &indices);
        self.skin_index.len = indices.len() as u32 * 3;
        let a = self.surface_faces.write(device, queue, &surface);
        let b = self.cut_faces.write(device, queue, &cut);
        a | b
    }

    /// Unique edges of the live tets.
    fn rebuild_edges(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        state: &BodyState<'_>,
    ) -> bool {
        let live = state.cut.live();
        let mut edges: Vec<[u32; 2]> = self
            .tets
            .iter()
            .enumerate()
            .filter(|(t, _)| live.get(*t).copied().unwrap_or(true))
            .flat_map(|(_, tet)| {
                TET_EDGES.iter().map(move |&(a, b)| {
                    let (i, j) = (tet[a], tet[b]);
                    [i.min(j), i.max(j)]
                })
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        self.edges.write(device, queue, &edges)
    }

    fn update_markers(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        state: &BodyState<'_>,
        settings: &RenderSettings,
    ) {
        let mut markers = Vec::new();
        if settings.overlays.tool_spheres {
            markers.extend(settings.tool.spheres.iter().map(|&(c, r)| Marker {
                centre_radius: [c.x, c.y, c.z, r],
                colour: [0.20, 0.55, 0.95, 1.0],
            }));
        }
        if settings.overlays.pinned {
            markers.extend(
                state
                    .pinned
                    .iter()
                    .filter_map(|&i| state.positions.get(i as usize))
                    .map(|p: &Vec3| Marker {
                        centre_radius: [p.x, p.y, p.z, self.pin_radius],
                        colour: [0.95, 0.75, 0.10, 1.0],
                    }),
            );
        }
        self.markers.write(device, queue, &markers);
    }
}
