//! The implicit (Newton) scheme on the device (docs/physics-notes.md, "The implicit scheme
//! on the GPU"): the CPU's scheme (`crate::implicit`, the readable reference) with its
//! per-tet evaluation, gradient and diagonal-block gather, matrix-free Hessian product,
//! two-level preconditioned conjugate gradient and backtracking line search as compute
//! kernels (`shaders/newton_*.wgsl`), driven from the host one Newton iteration at a time
//! (`drive.rs`), and the coarse level's factor kept on the host (`coarse.rs`).

mod coarse;
mod drive;
mod kernels;
mod layout;

pub use coarse::MAX_COARSE_NODES;
pub(crate) use drive::OnDevice;
pub use kernels::{NEWTON_STAGES, newton_source};

use wgpu::util::DeviceExt;

use super::GpuError;
use crate::implicit::{NewtonParams, NewtonReport, Scheme, Smoother};
use crate::xpbd::{NodeKind, Solver};
use coarse::HostCoarse;
use kernels::NewtonKernels;
use layout::{
    COARSE_NODES_OFFSET, FALL_OFFSET, GROUP, INV_H2_OFFSET, NewtonUniform, Scratch, TET_STRIDE,
    V_MASS, V_SLICES,
};

/// The XPBD solver's device buffers the Newton kernels read and write too.
pub(crate) struct Shared<'a> {
    /// Node displacements (w: inverse mass): the Newton iterate.
    pub pos: &'a wgpu::Buffer,
    /// Tet nodes per slot.
    pub tets: &'a wgpu::Buffer,
    /// `Dm⁻¹` and rest volume per slot.
    pub rest: &'a wgpu::Buffer,
    /// Live flag per slot.
    pub live: &'a wgpu::Buffer,
    /// Node kinds.
    pub kind: &'a wgpu::Buffer,
    /// The contact's per-node push (the held nodes' reactions go there).
    pub push: &'a wgpu::Buffer,
}

/// The Newton kernels' own buffers.
struct Buffers {
    uniform: wgpu::Buffer,
    /// Node vectors, `V_SLICES` slices of `vec4` (newton_common.wgsl).
    vecs: wgpu::Buffer,
    /// Per slot: forces, diagonal blocks, tangent, product (`TET_STRIDE` vec4).
    tet_out: wgpu::Buffer,
    /// Per node, the range of its (slot, corner) entries, then the entries.
    inc: wgpu::Buffer,
    coarse_map: wgpu::Buffer,
    /// The coarse right-hand side, then the coarse solution.
    coarse_vec: wgpu::Buffer,
    /// Dense `A_c⁻¹`.
    ainv: wgpu::Buffer,
    /// Partial sums and the conjugate gradient's state.
    scratch: wgpu::Buffer,
    read_scratch: wgpu::Buffer,
}

/// Group 0 of each stage.
struct Bindings {
    tets: wgpu::BindGroup,
    nodes: wgpu::BindGroup,
    cg: wgpu::BindGroup,
}

/// The implicit scheme's device state for one body.
pub(crate) struct GpuNewton {
    params: NewtonParams,
    kernels: NewtonKernels,
    buf: Buffers,
    bind: Bindings,
    coarse: HostCoarse,
    scratch: Scratch,
    /// Workgroups of a node, a tet and a coarse-row dispatch.
    groups: (u32, u32, u32),
    inv_h2: f32,
    /// Gravity, for the starting point's fall at another step length.
    gravity: glam::Vec3,
    /// The mesh's mean rest edge, m (the step stop's unit).
    mean_edge: f32,
    node_count: usize,
    /// The last step's cost.
    pub last: NewtonReport,
    /// Dispatches recorded since the caller last took the count.
    pub dispatches: u32,
    /// Products of the last conjugate-gradient solve: how many iterations the next one
    /// records before its first readback.
    cg_hint: u32,
    /// The coarse grid's generation the device holds ([`HostCoarse::generation`]).
    generation: u32,
}

fn storage(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let padded;
    let contents = if bytes.len() < 16 {
        padded = [bytes, &[0u8; 16][..16 - bytes.len()]].concat();
        &padded[..]
    } else {
        bytes
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
    })
}

fn bind(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    list: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = list
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

impl GpuNewton {
    /// The Newton kernels and buffers for `host` (scheme Newton, pins and grabs set), on
    /// `device`, beside the XPBD solver's `shared` buffers; builds and factorises the
    /// coarse level and uploads its inverse. `None` for an XPBD scene.
    pub fn new(
        device: &wgpu::Device,
        host: &Solver,
        shared: Shared<'_>,
        (adapter, max_binding): (&str, u64),
    ) -> Result<Option<Self>, GpuError> {
        let Scheme::Newton(params) = host.params.scheme else {
            return Ok(None);
        };
        if params.smoother == Smoother::GaussSeidel {
            return Err(GpuError::CpuOnlySmoother("GaussSeidel"));
        }
        let mesh = &host.mesh;
        let (n, slots) = (host.x.len(), host.slots.len());
        let h = host.params.step_length();
        let free: Vec<bool> = host.kind.iter().map(|k| *k == NodeKind::Free).collect();
        let team = host.team.as_ref();
        let mut coarse = HostCoarse::new(mesh, &host.mass, &free, (host.lame, h), &params, team)?;
        if coarse.nodes() > coarse::MAX_COARSE_NODES {
            return Err(GpuError::CoarseTooLarge {
                nodes: coarse.nodes(),
                max: coarse::MAX_COARSE_NODES,
            });
        }
        // Room for the grid a cut may split it into (implicit/coarse_rebuild.rs).
        let capacity = coarse.limit_nodes(coarse::MAX_COARSE_NODES);
        let rows = 3 * capacity;
        let too_large = |needed: u64| GpuError::TooLarge {
            adapter: adapter.to_string(),
            needed,
            limit: max_binding,
        };
        for needed in [
            V_SLICES * 16 * n as u64,
            TET_STRIDE * 16 * slots as u64,
            4 * (rows * rows) as u64,
            4 * HostCoarse::map_capacity(n, capacity) as u64,
        ] {
            if needed > max_binding {
                return Err(too_large(needed));
            }
        }
        let scratch = Scratch {
            tet_groups: slots.div_ceil(GROUP as usize),
            node_groups: n.div_ceil(GROUP as usize),
        };
        let (mut map, transpose_at) = coarse.map();
        map.resize(HostCoarse::map_capacity(n, capacity), 0);
        let mut ainv = coarse.inverse();
        ainv.resize(rows * rows, 0.0);
        let inv_h2 = 1.0 / (h * h);
        let uniform = NewtonUniform {
            node_count: n as u32,
            slot_count: slots as u32,
            coarse_nodes: coarse.nodes() as u32,
            max_products: params.cg_iterations,
            inv_h2,
            mu: host.lame.mu,
            lambda: host.lame.lambda,
            tol2: params.cg_tolerance * params.cg_tolerance,
            fall: (host.params.gravity * (h * h)).to_array(),
            alpha: 1.0,
            node_groups: scratch.node_groups as u32,
            tet_groups: scratch.tet_groups as u32,
            transpose_at,
            pad: 0,
        };
        let mut vecs = vec![[0.0f32; 4]; V_SLICES as usize * n];
        for (i, m) in host.mass.iter().enumerate() {
            vecs[V_MASS as usize * n + i][0] = *m;
        }
        let base = n as u32 + 1;
        let mut inc: Vec<u32> = mesh.node_tet_offsets.iter().map(|&o| base + o).collect();
        inc.extend(
            mesh.node_corners()
                .iter()
                .map(|&(t, a)| 4 * host.slot_of_tet[t as usize] + a as u32),
        );
        let buf = Buffers {
            uniform: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("newton uniform"),
                contents: bytemuck::bytes_of(&uniform),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            }),
            vecs: storage(device, "newton vectors", bytemuck::cast_slice(&vecs)),
            tet_out: storage(
                device,
                "newton tet evaluations",
                &vec![0u8; (TET_STRIDE * 16) as usize * slots],
            ),
            inc: storage(device, "newton incidence", bytemuck::cast_slice(&inc)),
            coarse_map: storage(device, "coarse map", bytemuck::cast_slice(&map)),
            coarse_vec: storage(device, "coarse vectors", &vec![0u8; 8 * rows]),
            ainv: storage(device, "coarse inverse", bytemuck::cast_slice(&ainv)),
            scratch: storage(device, "newton scratch", &vec![0u8; 4 * scratch.len()]),
            read_scratch: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("read newton scratch"),
                size: 4 * scratch.len() as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        };
        let kernels = NewtonKernels::new(device);
        let b = &buf;
        let bind = Bindings {
            tets: self::bind(
                device,
                &kernels.tets_layout,
                "newton tets",
                &[
                    &b.uniform,
                    shared.tets,
                    shared.rest,
                    shared.live,
                    &b.vecs,
                    &b.tet_out,
                    &b.scratch,
                ],
            ),
            nodes: self::bind(
                device,
                &kernels.nodes_layout,
                "newton nodes",
                &[
                    &b.uniform,
                    shared.pos,
                    &b.vecs,
                    shared.kind,
                    &b.tet_out,
                    &b.inc,
                    &b.scratch,
                    shared.push,
                    shared.live,
                ],
            ),
            cg: self::bind(
                device,
                &kernels.cg_layout,
                "newton cg",
                &[
                    &b.uniform,
                    &b.vecs,
                    shared.kind,
                    &b.coarse_map,
                    &b.coarse_vec,
                    &b.ainv,
                    &b.scratch,
                ],
            ),
        };
        let newton = GpuNewton {
            groups: (
                scratch.node_groups as u32,
                scratch.tet_groups as u32,
                (3 * coarse.nodes() as u32).div_ceil(GROUP),
            ),
            params,
            kernels,
            buf,
            bind,
            coarse,
            scratch,
            inv_h2,
            gravity: host.params.gravity,
            mean_edge: mesh.mean_edge_length(),
            node_count: n,
            last: NewtonReport::default(),
            dispatches: 0,
            cg_hint: 8,
            generation: 0,
        };
        Ok(Some(newton))
    }

    /// Solve the next steps at step length `h` (a frame run again at more steps under the
    /// blade): the inertia and the starting point's fall change; the coarse level keeps
    /// the scene's own step's inertia (it only preconditions), as on the CPU
    /// (`NewtonWorkspace::set_step_length`).
    pub fn set_step_length(&mut self, queue: &wgpu::Queue, h: f32) {
        let inv_h2 = 1.0 / (h * h);
        if inv_h2 == self.inv_h2 {
            return;
        }
        self.inv_h2 = inv_h2;
        queue.write_buffer(
            &self.buf.uniform,
            INV_H2_OFFSET,
            bytemuck::bytes_of(&inv_h2),
        );
        let fall = (self.gravity * (h * h)).to_array();
        queue.write_buffer(&self.buf.uniform, FALL_OFFSET, bytemuck::cast_slice(&fall));
    }

    /// Take released tets (mesh indices) out of the coarse level; its new factor and
    /// inverse follow at [`GpuNewton::settle_coarse`] (as on the CPU).
    pub fn release(&mut self, tets: &[u32]) {
        self.coarse.release(tets);
    }

    /// Refactorise the coarse level after releases and upload its new inverse (about
    /// 16 ms on the host for the default organ's 1,041 coarse rows, 2 cores), unless the
    /// coming step refreshes it anyway: by the next step, or ahead of the frame by
    /// `GpuSolver::prepare_frame`, to the same bits. Whether there was one to do.
    pub fn settle_coarse(&mut self, queue: &wgpu::Queue) -> bool {
        let changed = self.coarse.settle(&self.last);
        if changed {
            self.upload_inverse(queue);
        }
        changed
    }

    /// Write the coarse level to the device after a refresh: its grid, where a cut
    /// rebuilt it (the map, the node count and the coarse workgroups), and its inverse.
    fn upload_coarse(&mut self, queue: &wgpu::Queue) {
        let generation = self.coarse.generation();
        if generation != self.generation {
            self.generation = generation;
            let (map, _) = self.coarse.map();
            queue.write_buffer(&self.buf.coarse_map, 0, bytemuck::cast_slice(&map));
            let nodes = self.coarse.nodes() as u32;
            queue.write_buffer(
                &self.buf.uniform,
                COARSE_NODES_OFFSET,
                bytemuck::bytes_of(&nodes),
            );
            self.groups.2 = (3 * nodes).div_ceil(GROUP);
        }
        self.upload_inverse(queue);
    }

    /// Write the coarse level's current inverse to the device.
    fn upload_inverse(&self, queue: &wgpu::Queue) {
        if self.coarse.nodes() > 0 {
            queue.write_buffer(
                &self.buf.ainv,
                0,
                bytemuck::cast_slice(&self.coarse.inverse()),
            );
        }
    }
}
