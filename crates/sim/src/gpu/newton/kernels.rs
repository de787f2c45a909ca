//! The Newton kernels' WGSL sources (common.wgsl and newton_common.wgsl prepended to each
//! stage), their bind group layouts and compiled pipelines.

/// The Newton stages; each is `gpu/newton/shaders/<name>.wgsl`.
pub const NEWTON_STAGES: [&str; 3] = ["newton_tets", "newton_nodes", "newton_cg"];

const COMMON: &str = include_str!("../shaders/common.wgsl");
const NEWTON_COMMON: &str = include_str!("shaders/newton_common.wgsl");

/// Full WGSL source of a Newton stage, or `None` if unknown.
pub fn newton_source(stage: &str) -> Option<String> {
    let body = match stage {
        "newton_tets" => include_str!("shaders/newton_tets.wgsl"),
        "newton_nodes" => include_str!("shaders/newton_nodes.wgsl"),
        "newton_cg" => include_str!("shaders/newton_cg.wgsl"),
        _ => return None,
    };
    Some(format!("{COMMON}\n{NEWTON_COMMON}\n{body}"))
}

/// How a stage binds one slot of its group 0.
#[derive(Clone, Copy)]
enum Slot {
    Uniform,
    Read,
    Write,
}

/// Group 0 of each stage, binding by binding (binding 0 is the `Newton` uniform).
const TETS: [Slot; 7] = [
    Slot::Uniform,
    Slot::Read,
    Slot::Read,
    Slot::Read,
    Slot::Read,
    Slot::Write,
    Slot::Write,
];
const NODES: [Slot; 9] = [
    Slot::Uniform,
    Slot::Write,
    Slot::Write,
    Slot::Read,
    Slot::Read,
    Slot::Read,
    Slot::Write,
    Slot::Write,
    Slot::Read,
];
const CG: [Slot; 7] = [
    Slot::Uniform,
    Slot::Write,
    Slot::Read,
    Slot::Read,
    Slot::Write,
    Slot::Read,
    Slot::Write,
];

/// The pipelines of every Newton entry point, with the layout of each stage's group 0
/// (one layout a stage, so every entry point of a stage takes the same bind group).
pub(crate) struct NewtonKernels {
    pub tets_layout: wgpu::BindGroupLayout,
    pub nodes_layout: wgpu::BindGroupLayout,
    pub cg_layout: wgpu::BindGroupLayout,
    pub evaluate: wgpu::ComputePipeline,
    pub energy: wgpu::ComputePipeline,
    pub product: wgpu::ComputePipeline,
    pub start: wgpu::ComputePipeline,
    pub gather: wgpu::ComputePipeline,
    pub inertia: wgpu::ComputePipeline,
    pub trial: wgpu::ComputePipeline,
    pub gather_product: wgpu::ComputePipeline,
    pub resume: wgpu::ComputePipeline,
    pub reaction: wgpu::ComputePipeline,
    pub unload: wgpu::ComputePipeline,
    pub restrict_init: wgpu::ComputePipeline,
    pub coarse_solve: wgpu::ComputePipeline,
    pub precondition_init: wgpu::ComputePipeline,
    pub step_restrict: wgpu::ComputePipeline,
    pub update: wgpu::ComputePipeline,
}

impl NewtonKernels {
    /// Compile every stage.
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = |label: &str, slots: &[Slot]| {
            let entries: Vec<wgpu::BindGroupLayoutEntry> = slots
                .iter()
                .enumerate()
                .map(|(i, s)| wgpu::BindGroupLayoutEntry {
                    binding: i as u32,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: match s {
                            Slot::Uniform => wgpu::BufferBindingType::Uniform,
                            Slot::Read => wgpu::BufferBindingType::Storage { read_only: true },
                            Slot::Write => wgpu::BufferBindingType::Storage { read_only: false },
                        },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect();
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &entries,
            })
        };
        let tets_layout = layout("newton tets", &TETS);
        let nodes_layout = layout("newton nodes", &NODES);
        let cg_layout = layout("newton cg", &CG);
        let module = |stage: &str| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(stage),
                source: wgpu::ShaderSource::Wgsl(newton_source(stage).unwrap_or_default().into()),
            })
        };
        let (tets, nodes, cg) = (
            module("newton_tets"),
            module("newton_nodes"),
            module("newton_cg"),
        );
        let pipeline = |m: &wgpu::ShaderModule, group: &wgpu::BindGroupLayout, entry: &str| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry),
                bind_group_layouts: &[Some(group)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&layout),
                module: m,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        NewtonKernels {
            evaluate: pipeline(&tets, &tets_layout, "evaluate"),
            energy: pipeline(&tets, &tets_layout, "energy"),
            product: pipeline(&tets, &tets_layout, "product"),
            start: pipeline(&nodes, &nodes_layout, "start"),
            gather: pipeline(&nodes, &nodes_layout, "gather"),
            inertia: pipeline(&nodes, &nodes_layout, "inertia"),
            trial: pipeline(&nodes, &nodes_layout, "trial"),
            gather_product: pipeline(&nodes, &nodes_layout, "gather_product"),
            resume: pipeline(&nodes, &nodes_layout, "resume"),
            reaction: pipeline(&nodes, &nodes_layout, "reaction"),
            unload: pipeline(&nodes, &nodes_layout, "unload"),
            restrict_init: pipeline(&cg, &cg_layout, "restrict_init"),
            coarse_solve: pipeline(&cg, &cg_layout, "coarse_solve"),
            precondition_init: pipeline(&cg, &cg_layout, "precondition_init"),
            step_restrict: pipeline(&cg, &cg_layout, "step_restrict"),
            update: pipeline(&cg, &cg_layout, "update"),
            tets_layout,
            nodes_layout,
            cg_layout,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every Newton stage parses and validates with naga, without an adapter.
    #[test]
    fn newton_shaders_validate_with_naga() {
        for stage in NEWTON_STAGES {
            let src = newton_source(stage).unwrap();
            let module = wgpu::naga::front::wgsl::parse_str(&src)
                .unwrap_or_else(|e| panic!("{stage}.wgsl: {}", e.emit_to_string(&src)));
            wgpu::naga::valid::Validator::new(
                wgpu::naga::valid::ValidationFlags::all(),
                wgpu::naga::valid::Capabilities::empty(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{stage}.wgsl: {}", e.emit_to_string(&src)));
        }
    }
}
