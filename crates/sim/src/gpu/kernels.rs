//! The WGSL kernels: sources (common.wgsl prepended to each stage) and compiled pipelines.

/// The compute stages, in the order a frame runs them; each is `gpu/shaders/<name>.wgsl`.
pub const SHADER_STAGES: [&str; 6] = [
    "predict",
    "neo_hookean",
    "contact",
    "velocity",
    "stress",
    "release",
];

const COMMON: &str = include_str!("shaders/common.wgsl");

/// Full WGSL source of a stage (common definitions + the stage), or `None` if unknown.
pub fn shader_source(stage: &str) -> Option<String> {
    let body = match stage {
        "predict" => include_str!("shaders/predict.wgsl"),
        "neo_hookean" => include_str!("shaders/neo_hookean.wgsl"),
        "contact" => include_str!("shaders/contact.wgsl"),
        "velocity" => include_str!("shaders/velocity.wgsl"),
        "stress" => include_str!("shaders/stress.wgsl"),
        "release" => include_str!("shaders/release.wgsl"),
        _ => return None,
    };
    Some(format!("{COMMON}\n{body}"))
}

/// One compute pipeline per stage.
pub(crate) struct Kernels {
    pub predict: wgpu::ComputePipeline,
    pub project: wgpu::ComputePipeline,
    /// `neo_hookean.wgsl`'s `project_groups`: one phase of the partitioned order.
    pub project_groups: wgpu::ComputePipeline,
    pub contact: wgpu::ComputePipeline,
    /// `contact.wgsl`'s `hold`: the blade before an implicit step's solve.
    pub contact_hold: wgpu::ComputePipeline,
    /// `contact.wgsl`'s `resolve`: the nodes a solve carried into the tool, held.
    pub contact_resolve: wgpu::ComputePipeline,
    pub velocity: wgpu::ComputePipeline,
    pub stress: wgpu::ComputePipeline,
    pub release: wgpu::ComputePipeline,
    /// `release.wgsl`'s `clear_window`: restart the cut-zone window after a check.
    pub clear_window: wgpu::ComputePipeline,
    /// `release.wgsl`'s `clear_frame`: clear the frame's near-edge bit.
    pub clear_frame: wgpu::ComputePipeline,
}

impl Kernels {
    /// Compile every stage (layouts are derived from the shaders).
    pub fn new(device: &wgpu::Device) -> Self {
        let make_entry = |stage: &str, entry: &str| {
            let src = shader_source(stage).unwrap_or_default();
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(stage),
                source: wgpu::ShaderSource::Wgsl(src.into()),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(stage),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let make = |stage: &str| make_entry(stage, "main");
        Kernels {
            predict: make("predict"),
            project: make("neo_hookean"),
            project_groups: make_entry("neo_hookean", "project_groups"),
            contact: make("contact"),
            contact_hold: make_entry("contact", "hold"),
            contact_resolve: make_entry("contact", "resolve"),
            velocity: make("velocity"),
            stress: make("stress"),
            release: make("release"),
            clear_window: make_entry("release", "clear_window"),
            clear_frame: make_entry("release", "clear_frame"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every stage parses and validates with naga, without an adapter.
    #[test]
    fn all_shaders_validate_with_naga() {
        for stage in SHADER_STAGES {
            let src = shader_source(stage).unwrap();
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
