//! `GpuSolver`: persistent device buffers and one command encoder per frame (all substeps,
//! all colours, stress and release), with the CPU `Solver` as host mirror. Under
//! `scheme: Newton` a frame is the implicit steps of `gpu/newton/` instead of the
//! substeps (`solver/newton_frame.rs`), with the same prediction, contact, velocity,
//! stress and release kernels around them.

mod newton_frame;

use std::time::Instant;

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::kernels::Kernels;
use super::layout::{
    KIND_FREE, KIND_GRAB0, KIND_PINNED, KIND_RETIRED, Params, STEP_STRIDE, Step, TetRest,
};
use super::newton::{GpuNewton, Shared};
use super::readback::read_mapped;
use super::{GpuContext, GpuError};
use crate::Solver;
use crate::contact::{ContactTool, CutZone, PlacedTool, ToolPose};
use crate::implicit::Scheme;
use crate::stress::StressMeasure;
use crate::xpbd::{
    ConstraintPair, CpuSweep, FrameStats, MAX_SPLITS, NodeKind, SolverError, SolverParams,
    TetProjection, release_checks,
};

const WG: u32 = 64;

/// GPU time of the last frame, when the adapter supports timestamps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuTiming {
    /// Kernel time of the whole frame (all substeps + stress + release), ms.
    pub frame_ms: f64,
}

/// Device buffers of one body.
struct Buffers {
    params: wgpu::Buffer,
    steps: wgpu::Buffer,
    pos: wgpu::Buffer,
    prev: wgpu::Buffer,
    vel: wgpu::Buffer,
    start: wgpu::Buffer,
    kind: wgpu::Buffer,
    grab_offsets: wgpu::Buffer,
    tets: wgpu::Buffer,
    /// The partitioned order's slot runs per group and colour, and each phase's groups.
    runs: wgpu::Buffer,
    phase_groups: wgpu::Buffer,
    rest: wgpu::Buffer,
    live: wgpu::Buffer,
    saved_live: wgpu::Buffer,
    lambda: wgpu::Buffer,
    von_mises: wgpu::Buffer,
    det_f: wgpu::Buffer,
    rotation: wgpu::Buffer,
    released_count: wgpu::Buffer,
    released_list: wgpu::Buffer,
    saved_pos: wgpu::Buffer,
    saved_vel: wgpu::Buffer,
    /// `touch` and `near_edge` at the frame's start (a frame taken back restores them).
    saved_touch: wgpu::Buffer,
    saved_near_edge: wgpu::Buffer,
    rest_pos: wgpu::Buffer,
    tool: wgpu::Buffer,
    push: wgpu::Buffer,
    near_edge: wgpu::Buffer,
    /// Nodes the tool held through the last implicit step's solve (the host's `touched`).
    touch: wgpu::Buffer,
    /// How many nodes the contact kernel's `resolve` held (one counter).
    moved: wgpu::Buffer,
}

/// Bind groups for every dispatch of a frame.
struct Bindings {
    predict: wgpu::BindGroup,
    predict_steps: Vec<wgpu::BindGroup>,
    project: wgpu::BindGroup,
    project_steps: Vec<wgpu::BindGroup>,
    project_groups: wgpu::BindGroup,
    phase_steps: Vec<wgpu::BindGroup>,
    contact: wgpu::BindGroup,
    contact_steps: Vec<wgpu::BindGroup>,
    contact_hold: wgpu::BindGroup,
    hold_steps: Vec<wgpu::BindGroup>,
    contact_resolve: wgpu::BindGroup,
    resolve_steps: Vec<wgpu::BindGroup>,
    velocity: wgpu::BindGroup,
    stress: wgpu::BindGroup,
    release: wgpu::BindGroup,
    clear_window: wgpu::BindGroup,
    clear_frame: wgpu::BindGroup,
}

/// Mappable copies of what the host reads each frame.
struct Readback {
    pos: wgpu::Buffer,
    vel: wgpu::Buffer,
    von_mises: wgpu::Buffer,
    det_f: wgpu::Buffer,
    released: wgpu::Buffer,
    push: wgpu::Buffer,
    near_edge: wgpu::Buffer,
    moved: wgpu::Buffer,
}

struct Timestamps {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    period_ns: f32,
}

/// The XPBD solver on a wgpu device. Set pins and grabs on the CPU [`Solver`] first, then
/// move it onto the device with [`GpuSolver::new`]; accessors for positions, stress and
/// the cut state are those of the host mirror ([`GpuSolver::host`]), refreshed each frame.
pub struct GpuSolver {
    host: Solver,
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: String,
    kernels: Kernels,
    buf: Buffers,
    bind: Bindings,
    read: Readback,
    timestamps: Option<Timestamps>,
    last_timing: Option<GpuTiming>,
    offsets: Vec<[f32; 4]>,
    params: Params,
    tool_words: Vec<[f32; 4]>,
    fault: super::context::DeviceFault,
    /// The implicit scheme's kernels and coarse level (`None` under XPBD).
    newton: Option<GpuNewton>,
}

fn storage(
    device: &wgpu::Device,
    label: &str,
    bytes: &[u8],
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytes,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST
            | extra,
    })
}

fn staging(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn groups(n: usize) -> u32 {
    (n as u32).div_ceil(WG)
}

fn kind_code(k: NodeKind) -> u32 {
    match k {
        NodeKind::Free => KIND_FREE,
        NodeKind::Pinned => KIND_PINNED,
        NodeKind::Retired => KIND_RETIRED,
        NodeKind::Grabbed(g) => KIND_GRAB0 + g,
    }
}

fn entries<'a>(list: &[&'a wgpu::Buffer]) -> Vec<wgpu::BindGroupEntry<'a>> {
    list.iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect()
}

impl GpuSolver {
    /// Upload `host`'s state (mesh, rest data, colouring, pins, grabs) to the device.
    pub fn new(mut host: Solver, ctx: &GpuContext) -> Result<Self, GpuError> {
        // The device keeps its own coarse level: the host's would be refactorised on every
        // release for nothing (it is built again if the CPU takes over, `into_host`).
        host.newton = None;
        let device = ctx.device.clone();
        let queue = ctx.queue.clone();
        let n = host.x.len();
        let slots = host.slots.len();
        let needed = (slots * std::mem::size_of::<TetRest>()).max(n * 16) as u64;
        if needed > ctx.max_binding {
            return Err(GpuError::TooLarge {
                adapter: ctx.info.name.clone(),
                needed,
                limit: ctx.max_binding,
            });
        }
        let kernels = Kernels::new(&device);
        let pos: Vec<[f32; 4]> = host
            .u
            .iter()
            .zip(&host.inv_mass)
            .map(|(p, &w)| [p.x, p.y, p.z, w])
            .collect();
        let vec4 =
            |v: &[Vec3]| -> Vec<[f32; 4]> { v.iter().map(|p| [p.x, p.y, p.z, 0.0]).collect() };
        let kinds: Vec<u32> = host.kind.iter().map(|&k| kind_code(k)).collect();
        let tets: Vec<[u32; 4]> = host.slots.iter().map(|s| s.nodes).collect();
        let rest: Vec<TetRest> = host
            .slots
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let m = s.terms.dm_inv;
                let v = host.mesh.rest_volume[host.tet_of_slot[i] as usize];
                TetRest {
                    // No volume constraint (λ = 0, infinite compliance): −1 on the device.
                    c0: [
                        m.x_axis.x,
                        m.x_axis.y,
                        m.x_axis.z,
                        finite_or_none(s.terms.alpha_h),
                    ],
                    c1: [m.y_axis.x, m.y_axis.y, m.y_axis.z, s.terms.alpha_d],
                    c2: [m.z_axis.x, m.z_axis.y, m.z_axis.z, v],
                }
            })
            .collect();
        let live: Vec<u32> = host.slots.iter().map(|s| s.live as u32).collect();
        let rot: Vec<[f32; 4]> = host
            .tet_of_slot
            .iter()
            .map(|&t| host.rotation[t as usize].to_array())
            .collect();
        let p = &host.params;
        let params = params_of(&host, p.steps());
        // Step records: one per substep or implicit step (prediction; under the implicit
        // scheme for a frame run at up to 2^MAX_SPLITS times its steps), then one per colour.
        let substeps = step_records(p);
        let colours = host.color_ranges.len();
        let phases = host.plan.phases.len();
        let mut step_bytes = vec![0u8; (substeps + colours + phases) * STEP_STRIDE as usize];
        let mut put = |k: usize, s: Step| {
            let o = k * STEP_STRIDE as usize;
            step_bytes[o..o + 16].copy_from_slice(bytemuck::bytes_of(&s));
        };
        for s in 0..substeps {
            put(
                s,
                Step {
                    first: 0,
                    count: n as u32,
                    substep: s as u32,
                    pad: 0,
                },
            );
        }
        for (c, r) in host.color_ranges.iter().enumerate() {
            put(
                substeps + c,
                Step {
                    first: r.start as u32,
                    count: r.len() as u32,
                    substep: 0,
                    pad: 0,
                },
            );
        }
        // Then one per phase of the partitioned order: its first group, and the colours.
        let mut phase_groups: Vec<u32> = Vec::new();
        for (k, phase) in host.plan.phases.iter().enumerate() {
            put(
                substeps + colours + k,
                Step {
                    first: phase_groups.len() as u32,
                    count: colours as u32,
                    substep: 0,
                    pad: 0,
                },
            );
            phase_groups.extend(phase.iter().map(|&g| g as u32));
        }
        let runs: Vec<[u32; 2]> = (host.plan.runs.iter())
            .flat_map(|g| g.iter().map(|r| [r.start as u32, r.end as u32]))
            .collect();
        let none = wgpu::BufferUsages::empty();
        let pos_b = storage(&device, "pos", bytemuck::cast_slice(&pos), none);
        let buf = Buffers {
            params: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            }),
            steps: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("steps"),
                contents: &step_bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            }),
            prev: storage(&device, "prev", bytemuck::cast_slice(&pos), none),
            saved_pos: storage(&device, "saved pos", bytemuck::cast_slice(&pos), none),
            pos: pos_b,
            vel: storage(&device, "vel", bytemuck::cast_slice(&vec4(&host.v)), none),
            saved_vel: storage(
                &device,
                "saved vel",
                bytemuck::cast_slice(&vec4(&host.v)),
                none,
            ),
            start: storage(
                &device,
                "start",
                bytemuck::cast_slice(&vec4(&host.start)),
                none,
            ),
            kind: storage(&device, "kind", bytemuck::cast_slice(&kinds), none),
            grab_offsets: storage(
                &device,
                "grab offsets",
                &vec![0u8; (substeps * host.grabs.len().max(1) * 16).max(16)],
                none,
            ),
            tets: storage(&device, "tets", bytemuck::cast_slice(&tets), none),
            runs: storage(&device, "runs", bytemuck::cast_slice(&runs), none),
            phase_groups: storage(
                &device,
                "phase groups",
                bytemuck::cast_slice(&phase_groups),
                none,
            ),
            rest: storage(&device, "rest", bytemuck::cast_slice(&rest), none),
            live: storage(&device, "live", bytemuck::cast_slice(&live), none),
            saved_live: storage(&device, "saved live", bytemuck::cast_slice(&live), none),
            lambda: storage(&device, "lambda_h", &vec![0u8; slots * 4], none),
            von_mises: storage(&device, "von mises", &vec![0u8; slots * 4], none),
            det_f: storage(
                &device,
                "det F",
                bytemuck::cast_slice(&vec![1.0f32; slots]),
                none,
            ),
            rotation: storage(&device, "rotation", bytemuck::cast_slice(&rot), none),
            released_count: storage(&device, "released count", &[0u8; 4], none),
            released_list: storage(&device, "released list", &vec![0u8; slots * 4], none),
            rest_pos: storage(
                &device,
                "rest positions",
                bytemuck::cast_slice(&vec4(&host.mesh.rest_positions)),
                none,
            ),
            tool: storage(&device, "tool", &[0u8; 16], none),
            push: storage(&device, "contact push", &vec![0u8; n * 16], none),
            near_edge: storage(&device, "near edge", &vec![0u8; n * 4], none),
            saved_near_edge: storage(&device, "saved near edge", &vec![0u8; n * 4], none),
            saved_touch: storage(&device, "saved touched", &vec![0u8; n * 4], none),
            touch: storage(
                &device,
                "touched",
                bytemuck::cast_slice(
                    &host
                        .touched
                        .iter()
                        .map(|&t| u32::from(t))
                        .collect::<Vec<u32>>(),
                ),
                none,
            ),
            moved: storage(&device, "held by resolve", &[0u8; 4], none),
        };
        let b = &buf;
        let group =
            |pipe: &wgpu::ComputePipeline, index: u32, list: &[&wgpu::Buffer], label: &str| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(label),
                    layout: &pipe.get_bind_group_layout(index),
                    entries: &entries(list),
                })
            };
        let step_group = |pipe: &wgpu::ComputePipeline, k: usize| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("step"),
                layout: &pipe.get_bind_group_layout(1),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &b.steps,
                        offset: k as u64 * STEP_STRIDE,
                        size: wgpu::BufferSize::new(16),
                    }),
                }],
            })
        };
        let bind = Bindings {
            predict: group(
                &kernels.predict,
                0,
                &[
                    &b.params,
                    &b.pos,
                    &b.prev,
                    &b.vel,
                    &b.start,
                    &b.kind,
                    &b.grab_offsets,
                ],
                "predict",
            ),
            predict_steps: (0..substeps)
                .map(|s| step_group(&kernels.predict, s))
                .collect(),
            project: group(
                &kernels.project,
                0,
                &[&b.params, &b.pos, &b.tets, &b.rest, &b.live, &b.lambda],
                "project",
            ),
            project_steps: (0..colours)
                .map(|c| step_group(&kernels.project, substeps + c))
                .collect(),
            project_groups: group(
                &kernels.project_groups,
                0,
                &[
                    &b.params,
                    &b.pos,
                    &b.tets,
                    &b.rest,
                    &b.live,
                    &b.lambda,
                    &b.runs,
                    &b.phase_groups,
                ],
                "project groups",
            ),
            phase_steps: (0..phases)
                .map(|k| step_group(&kernels.project_groups, substeps + colours + k))
                .collect(),
            contact: contact_group(&device, &kernels, b),
            contact_steps: (0..substeps)
                .map(|s| step_group(&kernels.contact, s))
                .collect(),
            contact_hold: hold_group(&device, &kernels, b),
            hold_steps: (0..substeps)
                .map(|s| step_group(&kernels.contact_hold, s))
                .collect(),
            contact_resolve: resolve_group(&device, &kernels, b),
            resolve_steps: (0..substeps)
                .map(|s| step_group(&kernels.contact_resolve, s))
                .collect(),
            velocity: group(
                &kernels.velocity,
                0,
                &[&b.params, &b.pos, &b.prev, &b.vel, &b.kind],
                "velocity",
            ),
            stress: group(
                &kernels.stress,
                0,
                &[
                    &b.params,
                    &b.pos,
                    &b.tets,
                    &b.rest,
                    &b.live,
                    &b.von_mises,
                    &b.det_f,
                    &b.rotation,
                ],
                "stress",
            ),
            release: group(
                &kernels.release,
                0,
                &[
                    &b.params,
                    &b.von_mises,
                    &b.live,
                    &b.released_count,
                    &b.released_list,
                    &b.tets,
                    &b.near_edge,
                ],
                "release",
            ),
            clear_window: near_edge_group(&device, &kernels.clear_window, b),
            clear_frame: near_edge_group(&device, &kernels.clear_frame, b),
        };
        let read = Readback {
            pos: staging(&device, "read pos", n as u64 * 16),
            vel: staging(&device, "read vel", n as u64 * 16),
            von_mises: staging(&device, "read von mises", slots as u64 * 4),
            det_f: staging(&device, "read det F", slots as u64 * 4),
            released: staging(&device, "read released", 4 + slots as u64 * 4),
            push: staging(&device, "read contact push", n as u64 * 16),
            near_edge: staging(&device, "read near edge", n as u64 * 4),
            moved: staging(&device, "read held by resolve", 4),
        };
        let newton = GpuNewton::new(
            &device,
            &host,
            Shared {
                pos: &buf.pos,
                tets: &buf.tets,
                rest: &buf.rest,
                live: &buf.live,
                kind: &buf.kind,
                push: &buf.push,
            },
            (&ctx.info.name, ctx.max_binding),
        )?;
        // A Newton frame spans several submissions: no pass brackets it (no GPU timing).
        let timestamps = (ctx.timestamps && newton.is_none()).then(|| Timestamps {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            read: staging(&device, "read timestamps", 16),
            period_ns: queue.get_timestamp_period(),
        });
        Ok(GpuSolver {
            adapter: ctx.describe(),
            offsets: vec![[0.0; 4]; substeps * host.grabs.len().max(1)],
            host,
            device,
            queue,
            kernels,
            buf,
            bind,
            read,
            timestamps,
            last_timing: None,
            params,
            tool_words: Vec::new(),
            fault: ctx.fault.clone(),
            newton,
        })
    }

    /// Give back the host mirror: the solver state as of the last completed frame (to go
    /// on with the CPU solver after a device failure).
    pub fn into_host(self) -> Solver {
        self.host
    }

    /// Fault injection for tests: destroy the device, as a driver reset or an unplugged
    /// GPU would; the next frame fails with `SolverError::Device`.
    pub fn inject_device_loss(&self) {
        self.device.destroy();
    }

    /// Fault injection for tests: a NaN velocity for `node` on the device (see
    /// [`Solver::inject_non_finite`]).
    pub fn inject_non_finite(&self, node: usize) {
        if node < self.host.x.len() {
            self.queue.write_buffer(
                &self.buf.vel,
                node as u64 * 16,
                bytemuck::bytes_of(&[f32::NAN; 4]),
            );
        }
    }

    fn check_device(&self) -> Result<(), SolverError> {
        match self.fault.get() {
            Some(msg) => Err(SolverError::Device(msg)),
            None => Ok(()),
        }
    }

    /// Attach a tool at `pose` (see [`Solver::set_tool`]).
    pub fn set_tool(&mut self, tool: ContactTool, pose: ToolPose) -> Result<(), SolverError> {
        self.host.set_tool(tool, pose)
    }

    /// Where the tool will be at the end of the next frame (see [`Solver::move_tool`]).
    pub fn move_tool(&mut self, to: ToolPose) {
        self.host.move_tool(to);
    }

    /// Detach the tool.
    pub fn remove_tool(&mut self) {
        self.host.remove_tool();
    }

    /// The host mirror: mesh, cut state, positions, velocities, stress of the last frame.
    pub fn host(&self) -> &Solver {
        &self.host
    }

    /// The implicit scheme's last step (`None` under XPBD).
    pub fn newton_report(&self) -> Option<crate::implicit::NewtonReport> {
        self.newton.as_ref().map(|n| n.last)
    }

    /// Adapter name, backend and type.
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    /// Kernel time of the last frame, where the adapter has timestamps.
    pub fn last_timing(&self) -> Option<GpuTiming> {
        self.last_timing
    }

    /// The device's node buffer (`vec4<f32>` per node: xyz = displacement `u` from the
    /// rest position, w = inverse mass), for renderers that read the state without a
    /// round trip: world position = rest position + `u`.
    pub fn displacement_buffer(&self) -> &wgpu::Buffer {
        &self.buf.pos
    }

    /// Per-tet "live" flags on the device (`u32` per tet in colour order).
    pub fn live_buffer(&self) -> &wgpu::Buffer {
        &self.buf.live
    }

    /// Advance one frame on the device; then read positions, velocities, stress and the
    /// tets released this frame back into the host mirror, run the guards and update the
    /// cut state. On a guard failure the frame is rolled back on both sides.
    pub fn step_frame(&mut self) -> Result<FrameStats, SolverError> {
        let t0 = Instant::now();
        self.check_device()?;
        let steps = self.host.params.steps();
        // The implicit scheme under a blade: a frame that leaves more live tets inverted
        // is taken back and run at twice the steps (CPU twin: Solver::run_implicit_steps).
        let split = self.newton.is_some() && self.host.tool.is_some();
        let inverted = if split {
            self.host.inverted_live_tets(&[])
        } else {
            0
        };
        self.host.implicit_cost = Default::default();
        let (mut n, mut passes) = (steps, 0);
        // The mesh tets the frame's release checks switched off on the device.
        let mesh_tets = loop {
            let gone: Vec<u32> = (self.run_frame(n)?.iter())
                .map(|&s| self.host.tet_of_slot[s as usize])
                .collect();
            passes += self.host.passes;
            if !split || n >= steps << MAX_SPLITS || self.host.inverted_live_tets(&gone) <= inverted
            {
                break gone;
            }
            self.restore_saved();
            self.host.implicit_cost.split_frames += 1;
            n *= 2;
        };
        self.host.passes = passes;
        // Device work ends when the readback completes: that is the frame's solve time.
        let t1 = Instant::now();
        let solve_ms = (t1 - t0).as_secs_f64() * 1e3;
        self.host.time += self.host.params.frame_dt as f64;
        let guard = self
            .host
            .check_finite()
            .and_then(|_| self.host.check_inversion());
        if let Err(e) = guard {
            self.roll_back();
            return Err(e);
        }
        let ev = self.host.release(&mesh_tets);
        self.retire_on_device(&ev.retired_nodes);
        if let Some(newton) = &mut self.newton {
            newton.release(&ev.tets);
        }
        if let Some(m) = &mut self.host.tool {
            m.from = m.to;
        }
        let mut stats = self.host.stats(ev.tets.len());
        stats.solve_ms = solve_ms;
        stats.stress_ms = t1.elapsed().as_secs_f64() * 1e3;
        stats.ahead_ms = std::mem::take(&mut self.host.ahead_ms);
        self.host.frame += 1;
        Ok(stats)
    }

    /// Do now what the coming frame can do before it knows the tool's pose
    /// (`Solver::prepare_frame`'s twin): under `scheme: Newton`, the coarse level's
    /// refactorisation and inverse upload after the last frame's releases. Its time is the
    /// next frame's `ahead_ms`.
    pub fn prepare_frame(&mut self) {
        let started = Instant::now();
        if let Some(newton) = &mut self.newton
            && newton.settle_coarse(&self.queue)
        {
            self.host.ahead_ms += started.elapsed().as_secs_f64() * 1e3;
        }
    }

    /// One attempt at the frame in `n` steps: upload, record, submit and read back into
    /// the host mirror; returns the slots released. A device fault restores the host's
    /// last good state.
    fn run_frame(&mut self, n: u32) -> Result<Vec<u32>, SolverError> {
        if let Some(newton) = &mut self.newton {
            newton.set_step_length(&self.queue, self.host.params.frame_dt / n as f32);
        }
        self.upload_grab_offsets(n);
        self.upload_tool(n);
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let (nodes, slots) = (self.host.x.len() as u64, self.host.slots.len() as u64);
        enc.copy_buffer_to_buffer(&self.buf.pos, 0, &self.buf.saved_pos, 0, nodes * 16);
        enc.copy_buffer_to_buffer(&self.buf.vel, 0, &self.buf.saved_vel, 0, nodes * 16);
        enc.copy_buffer_to_buffer(&self.buf.live, 0, &self.buf.saved_live, 0, slots * 4);
        enc.clear_buffer(&self.buf.released_count, 0, None);
        let with_tool = self.host.tool.is_some();
        if with_tool {
            enc.copy_buffer_to_buffer(&self.buf.touch, 0, &self.buf.saved_touch, 0, nodes * 4);
            enc.copy_buffer_to_buffer(
                &self.buf.near_edge,
                0,
                &self.buf.saved_near_edge,
                0,
                nodes * 4,
            );
            enc.clear_buffer(&self.buf.push, 0, None);
        }

        let mut enc = if self.newton.is_some() {
            self.record_newton_frame(enc, n)
                .map_err(|e| SolverError::Device(e.to_string()))?
        } else {
            self.host.passes = self.record_frame(&mut enc);
            enc
        };
        if with_tool {
            enc.copy_buffer_to_buffer(&self.buf.push, 0, &self.read.push, 0, nodes * 16);
            enc.copy_buffer_to_buffer(&self.buf.near_edge, 0, &self.read.near_edge, 0, nodes * 4);
        }
        enc.copy_buffer_to_buffer(&self.buf.pos, 0, &self.read.pos, 0, nodes * 16);
        enc.copy_buffer_to_buffer(&self.buf.vel, 0, &self.read.vel, 0, nodes * 16);
        enc.copy_buffer_to_buffer(&self.buf.von_mises, 0, &self.read.von_mises, 0, slots * 4);
        enc.copy_buffer_to_buffer(&self.buf.det_f, 0, &self.read.det_f, 0, slots * 4);
        enc.copy_buffer_to_buffer(&self.buf.released_count, 0, &self.read.released, 0, 4);
        enc.copy_buffer_to_buffer(
            &self.buf.released_list,
            0,
            &self.read.released,
            4,
            slots * 4,
        );
        if let Some(ts) = &self.timestamps {
            enc.resolve_query_set(&ts.queries, 0..2, &ts.resolve, 0);
            enc.copy_buffer_to_buffer(&ts.resolve, 0, &ts.read, 0, 16);
        }
        self.queue.submit([enc.finish()]);
        // The last good state, kept until the device has said the frame went well (a lost
        // device can map buffers of zeros).
        let good = (self.host.u.clone(), self.host.v.clone());
        let read = self
            .read_back()
            .map_err(|e| SolverError::Device(e.to_string()));
        match (read, self.fault.get()) {
            (Ok(r), None) => Ok(r),
            (read, fault) => {
                (self.host.u, self.host.v) = good;
                self.host.sync_positions();
                Err(match (fault, read) {
                    (Some(msg), _) => SolverError::Device(msg),
                    (None, Err(e)) => e,
                    (None, Ok(_)) => unreachable!("handled above"),
                })
            }
        }
    }

    /// Grab offsets at the ends of the frame's `n` steps.
    fn upload_grab_offsets(&mut self, n: u32) {
        let grabs = &self.host.grabs;
        if grabs.is_empty() {
            return;
        }
        let h = (self.host.params.frame_dt / n as f32) as f64;
        for s in 0..n as usize {
            let t = self.host.time + (s + 1) as f64 * h;
            for (g, grab) in grabs.iter().enumerate() {
                let o = grab.offset_at(t);
                self.offsets[s * grabs.len() + g] = [o.x, o.y, o.z, 0.0];
            }
        }
        self.queue.write_buffer(
            &self.buf.grab_offsets,
            0,
            bytemuck::cast_slice(&self.offsets),
        );
    }

    /// Parameters, primitive poses for every boundary of the frame's `n` steps and, when
    /// the tool's primitive count changed, a larger tool buffer.
    fn upload_tool(&mut self, n: u32) {
        let params = params_of(&self.host, n);
        if let Some(motion) = &self.host.tool {
            self.tool_words.clear();
            for k in 0..=n {
                push_placed(&mut self.tool_words, &motion.placed_at(k, n));
            }
            let bytes: &[u8] = bytemuck::cast_slice(&self.tool_words);
            if bytes.len() as u64 > self.buf.tool.size() {
                self.buf.tool = storage(&self.device, "tool", bytes, wgpu::BufferUsages::empty());
                self.bind.contact = contact_group(&self.device, &self.kernels, &self.buf);
                self.bind.contact_hold = hold_group(&self.device, &self.kernels, &self.buf);
                self.bind.contact_resolve = resolve_group(&self.device, &self.kernels, &self.buf);
            } else {
                self.queue.write_buffer(&self.buf.tool, 0, bytes);
            }
        }
        if bytemuck::bytes_of(&params) != bytemuck::bytes_of(&self.params) {
            self.params = params;
            self.queue
                .write_buffer(&self.buf.params, 0, bytemuck::bytes_of(&self.params));
        }
    }

    /// All dispatches of one frame in one compute pass; returns how many.
    fn record_frame(&self, enc: &mut wgpu::CommandEncoder) -> u32 {
        let n = self.host.x.len();
        let timestamp_writes =
            self.timestamps
                .as_ref()
                .map(|ts| wgpu::ComputePassTimestampWrites {
                    query_set: &ts.queries,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                });
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("xpbd frame"),
            timestamp_writes,
        });
        let k = &self.kernels;
        let p = &self.host.params;
        let checks = release_checks(self.host.time, p.substep(), p.substeps, p.release_interval);
        let mut fresh = false;
        // The frame's bit of the near-edge flags clears with or without a tool (the release
        // window's bit carries over to the next check).
        pass.set_pipeline(&k.clear_frame);
        pass.set_bind_group(0, &self.bind.clear_frame, &[]);
        pass.dispatch_workgroups(groups(n), 1, 1);
        let mut dispatches = 1;
        for s in 0..self.host.params.substeps as usize {
            pass.set_pipeline(&k.predict);
            pass.set_bind_group(0, &self.bind.predict, &[]);
            pass.set_bind_group(1, &self.bind.predict_steps[s], &[]);
            pass.dispatch_workgroups(groups(n), 1, 1);
            dispatches += 2 + self.record_sweep(&mut pass);
            if self.host.tool.is_some() {
                dispatches += 1;
                pass.set_pipeline(&k.contact);
                pass.set_bind_group(0, &self.bind.contact, &[]);
                pass.set_bind_group(1, &self.bind.contact_steps[s], &[]);
                pass.dispatch_workgroups(groups(n), 1, 1);
            }
            pass.set_pipeline(&k.velocity);
            pass.set_bind_group(0, &self.bind.velocity, &[]);
            pass.dispatch_workgroups(groups(n), 1, 1);
            fresh = checks.contains(&(s as u32));
            if fresh {
                dispatches += self.record_release_check(&mut pass);
            }
        }
        if !fresh {
            // Stress and det F at the end of the frame, for the guards and the report.
            dispatches += self.record_stress(&mut pass);
        }
        dispatches
    }

    /// One sweep over the tets in the order the solver's settings choose (the CPU's
    /// `cpu_sweep`, so that both follow one Gauss–Seidel order): a dispatch per colour, or
    /// per phase of the partitioned order; returns the dispatch count.
    fn record_sweep(&self, pass: &mut wgpu::ComputePass<'_>) -> u32 {
        let k = &self.kernels;
        match self.host.params.cpu_sweep {
            CpuSweep::Coloured => {
                pass.set_pipeline(&k.project);
                pass.set_bind_group(0, &self.bind.project, &[]);
                for (c, r) in self.host.color_ranges.iter().enumerate() {
                    pass.set_bind_group(1, &self.bind.project_steps[c], &[]);
                    pass.dispatch_workgroups(groups(r.len()), 1, 1);
                }
                self.host.color_ranges.len() as u32
            }
            CpuSweep::Blocks => {
                pass.set_pipeline(&k.project_groups);
                pass.set_bind_group(0, &self.bind.project_groups, &[]);
                for (p, phase) in self.host.plan.phases.iter().enumerate() {
                    pass.set_bind_group(1, &self.bind.phase_steps[p], &[]);
                    pass.dispatch_workgroups(phase.len() as u32, 1, 1);
                }
                self.host.plan.phases.len() as u32
            }
        }
    }

    /// The stress pass; returns its dispatch count (1).
    fn record_stress(&self, pass: &mut wgpu::ComputePass<'_>) -> u32 {
        pass.set_pipeline(&self.kernels.stress);
        pass.set_bind_group(0, &self.bind.stress, &[]);
        pass.dispatch_workgroups(groups(self.host.slots.len()), 1, 1);
        1
    }

    /// Stress, release and the restart of the cut-zone window (PHYSICS.md §1.4 on the
    /// fixed interval; CPU twin: the check in `Solver::run_substeps`); returns its
    /// dispatch count.
    fn record_release_check(&self, pass: &mut wgpu::ComputePass<'_>) -> u32 {
        self.record_stress(pass);
        pass.set_pipeline(&self.kernels.release);
        pass.set_bind_group(0, &self.bind.release, &[]);
        pass.dispatch_workgroups(groups(self.host.slots.len()), 1, 1);
        pass.set_pipeline(&self.kernels.clear_window);
        pass.set_bind_group(0, &self.bind.clear_window, &[]);
        pass.dispatch_workgroups(groups(self.host.x.len()), 1, 1);
        3
    }

    /// Map the staging buffers, copy into the host mirror; returns released slots.
    fn read_back(&mut self) -> Result<Vec<u32>, GpuError> {
        let with_tool = self.host.tool.is_some();
        let mut bufs = vec![
            &self.read.pos,
            &self.read.vel,
            &self.read.von_mises,
            &self.read.det_f,
            &self.read.released,
        ];
        if with_tool {
            bufs.push(&self.read.push);
            bufs.push(&self.read.near_edge);
        }
        if let Some(ts) = &self.timestamps {
            bufs.push(&ts.read);
        }
        let mut got = read_mapped::<u8>(&self.device, &bufs)?.into_iter();
        let mut view = || got.next().unwrap_or_default();
        let (pos, vel, vm, det, rel) = (view(), view(), view(), view(), view());
        if with_tool {
            let (push, near) = (view(), view());
            let push: &[[f32; 4]] = bytemuck::cast_slice(&push);
            let near: &[u32] = bytemuck::cast_slice(&near);
            for (i, (p, e)) in push.iter().zip(near).enumerate() {
                self.host.contact_push[i] = Vec3::new(p[0], p[1], p[2]);
                self.host.near_edge[i] = *e & 1 != 0;
            }
        } else {
            self.host
                .contact_push
                .iter_mut()
                .for_each(|p| *p = Vec3::ZERO);
            self.host.near_edge.iter_mut().for_each(|e| *e = false);
        }
        if let Some(ts) = &self.timestamps {
            let t = view();
            let q: &[u64] = bytemuck::cast_slice(&t);
            self.last_timing = Some(GpuTiming {
                frame_ms: q[1].wrapping_sub(q[0]) as f64 * ts.period_ns as f64 * 1e-6,
            });
        }
        let pos: &[[f32; 4]] = bytemuck::cast_slice(&pos);
        let vel: &[[f32; 4]] = bytemuck::cast_slice(&vel);
        for (i, (p, v)) in pos.iter().zip(vel).enumerate() {
            self.host.u[i] = Vec3::new(p[0], p[1], p[2]);
            self.host.v[i] = Vec3::new(v[0], v[1], v[2]);
        }
        self.host.sync_positions();
        let vm: &[f32] = bytemuck::cast_slice(&vm);
        let det: &[f32] = bytemuck::cast_slice(&det);
        for (s, &t) in self.host.tet_of_slot.iter().enumerate() {
            self.host.von_mises[t as usize] = vm[s];
            if self.host.cut.is_live(t as usize) {
                self.host.det_f[t as usize] = det[s];
            }
        }
        let words: &[u32] = bytemuck::cast_slice(&rel);
        let count = (words[0] as usize).min(words.len() - 1);
        let mut released = words[1..1 + count].to_vec();
        released.sort_unstable();
        Ok(released)
    }

    /// Restore the frame's starting positions and velocities on both sides, and its
    /// clock.
    fn roll_back(&mut self) {
        self.restore_saved();
        self.host.time -= self.host.params.frame_dt as f64;
    }

    /// Restore the frame's starting state on both sides: positions, velocities, live
    /// tets and, with a tool, the nodes on the blade and the near-edge flags.
    fn restore_saved(&mut self) {
        let n = self.host.x.len() as u64;
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("rollback"),
            });
        enc.copy_buffer_to_buffer(&self.buf.saved_pos, 0, &self.buf.pos, 0, n * 16);
        enc.copy_buffer_to_buffer(&self.buf.saved_vel, 0, &self.buf.vel, 0, n * 16);
        if self.host.tool.is_some() {
            enc.copy_buffer_to_buffer(&self.buf.saved_touch, 0, &self.buf.touch, 0, n * 4);
            enc.copy_buffer_to_buffer(&self.buf.saved_near_edge, 0, &self.buf.near_edge, 0, n * 4);
        }
        let slots = self.host.slots.len() as u64;
        enc.copy_buffer_to_buffer(&self.buf.saved_live, 0, &self.buf.live, 0, slots * 4);
        enc.copy_buffer_to_buffer(&self.buf.saved_pos, 0, &self.read.pos, 0, n * 16);
        enc.copy_buffer_to_buffer(&self.buf.saved_vel, 0, &self.read.vel, 0, n * 16);
        self.queue.submit([enc.finish()]);
        let _ = self.read_state_only();
        self.host.sync_positions();
    }

    fn read_state_only(&mut self) -> Result<(), GpuError> {
        let got = read_mapped::<[f32; 4]>(&self.device, &[&self.read.pos, &self.read.vel])?;
        for (a, dst) in got.iter().zip([&mut self.host.u, &mut self.host.v]) {
            for (d, p) in dst.iter_mut().zip(a) {
                *d = Vec3::new(p[0], p[1], p[2]);
            }
        }
        Ok(())
    }

    /// Mark newly retired nodes on the device (frozen, zero velocity).
    fn retire_on_device(&self, nodes: &[u32]) {
        for &i in nodes {
            self.queue.write_buffer(
                &self.buf.kind,
                i as u64 * 4,
                bytemuck::bytes_of(&KIND_RETIRED),
            );
            self.queue.write_buffer(
                &self.buf.vel,
                i as u64 * 16,
                bytemuck::bytes_of(&[0.0f32; 4]),
            );
        }
    }
}

/// The kernels' `Params` for the host's settings and tool (primitive counts and friction
/// of the attached tool, if any), the frame in `steps` steps.
fn params_of(host: &Solver, steps: u32) -> Params {
    let p = &host.params;
    let h = p.frame_dt / steps as f32;
    let (sphere_count, box_count, friction) = host.tool.as_ref().map_or((0, 0, 0.0), |m| {
        (
            m.tool.spheres.len() as u32,
            m.tool.boxes.len() as u32,
            m.tool.friction,
        )
    });
    Params {
        gravity: p.gravity.to_array(),
        h,
        inv_h: 1.0 / h,
        keep: (1.0 - p.damping * h).max(0.0),
        gamma: host.lame.gamma(p.hydrostatic),
        mu: host.lame.mu,
        threshold: p.release_threshold.unwrap_or(0.0),
        node_count: host.x.len() as u32,
        slot_count: host.slots.len() as u32,
        grab_count: host.grabs.len() as u32,
        mode: match p.projection {
            TetProjection::Coupled => 0,
            TetProjection::Sequential => 1,
        },
        sphere_count,
        box_count,
        friction,
        reach: match p.cut_zone {
            CutZone::NearEdge { reach } => reach,
            CutZone::Anywhere => -1.0,
        },
        lambda: host.volume_stiffness(),
        pair: match p.constraints {
            ConstraintPair::RestFree => 0,
            ConstraintPair::GammaShifted => 1,
        },
        measure: match p.stress {
            StressMeasure::Cauchy => 0,
            StressMeasure::PaperEq3 => 1,
        },
    }
}

/// Step records a frame may use: its substeps under XPBD; under the implicit scheme its
/// steps at up to `MAX_SPLITS` doublings (`Solver::run_implicit_steps`).
fn step_records(p: &SolverParams) -> usize {
    match p.scheme {
        Scheme::Newton(_) => (p.steps() << MAX_SPLITS) as usize,
        Scheme::Xpbd => p.steps() as usize,
    }
}

/// Bind group of a near-edge clearing kernel (`Params` at 0, `near_edge` at 6).
fn near_edge_group(
    device: &wgpu::Device,
    pipeline: &wgpu::ComputePipeline,
    b: &Buffers,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("near edge"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: b.params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 6,
                resource: b.near_edge.as_entire_binding(),
            },
        ],
    })
}

/// A compliance for the device: infinite (no constraint) becomes −1.
fn finite_or_none(alpha: f32) -> f32 {
    if alpha.is_finite() { alpha } else { -1.0 }
}

/// Append one pose block of the `tool` buffer (layout in `gpu/shaders/contact.wgsl`).
fn push_placed(words: &mut Vec<[f32; 4]>, placed: &PlacedTool) {
    words.push([placed.lo.x, placed.lo.y, placed.lo.z, 0.0]);
    words.push([placed.hi.x, placed.hi.y, placed.hi.z, 0.0]);
    for s in &placed.spheres {
        let r = if s.cutting { s.radius } else { -s.radius };
        words.push([s.centre.x, s.centre.y, s.centre.z, r]);
    }
    for b in &placed.boxes {
        words.push([b.centre.x, b.centre.y, b.centre.z, 0.0]);
        for (a, h) in [
            (b.axes.x_axis, b.half_extents.x),
            (b.axes.y_axis, b.half_extents.y),
            (b.axes.z_axis, b.half_extents.z),
        ] {
            words.push([a.x, a.y, a.z, h]);
        }
    }
}

/// The contact kernel's bind group (rebuilt when the tool buffer grows).
fn contact_group(device: &wgpu::Device, kernels: &Kernels, b: &Buffers) -> wgpu::BindGroup {
    let list = [
        &b.params,
        &b.pos,
        &b.prev,
        &b.kind,
        &b.rest_pos,
        &b.tool,
        &b.push,
        &b.near_edge,
        &b.touch,
    ];
    numbered_group(
        device,
        &kernels.contact,
        "contact",
        &list.iter().copied().zip(0..).collect::<Vec<_>>(),
    )
}

/// The bind group of the contact kernel's `hold` (rebuilt with [`contact_group`]).
fn hold_group(device: &wgpu::Device, kernels: &Kernels, b: &Buffers) -> wgpu::BindGroup {
    let pipe = &kernels.contact_hold;
    projection_group(device, pipe, "contact hold", b, (&b.touch, 8))
}

/// The bind group of the contact kernel's `resolve` (rebuilt with [`contact_group`]).
fn resolve_group(device: &wgpu::Device, kernels: &Kernels, b: &Buffers) -> wgpu::BindGroup {
    let pipe = &kernels.contact_resolve;
    projection_group(device, pipe, "contact resolve", b, (&b.moved, 9))
}

/// Group 0 of a contact entry point that projects without booking a push: what
/// contact.wgsl's `projected` reads and writes, and its own `extra` binding.
fn projection_group(
    device: &wgpu::Device,
    pipe: &wgpu::ComputePipeline,
    label: &str,
    b: &Buffers,
    extra: (&wgpu::Buffer, u32),
) -> wgpu::BindGroup {
    let list = [
        (&b.params, 0),
        (&b.pos, 1),
        (&b.prev, 2),
        (&b.kind, 3),
        (&b.rest_pos, 4),
        (&b.tool, 5),
        (&b.near_edge, 7),
        extra,
    ];
    numbered_group(device, pipe, label, &list)
}

/// Group 0 of `pipe` from buffers with their binding numbers.
fn numbered_group(
    device: &wgpu::Device,
    pipe: &wgpu::ComputePipeline,
    label: &str,
    list: &[(&wgpu::Buffer, u32)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = list
        .iter()
        .map(|(b, i)| wgpu::BindGroupEntry {
            binding: *i,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipe.get_bind_group_layout(0),
        entries: &entries,
    })
}
