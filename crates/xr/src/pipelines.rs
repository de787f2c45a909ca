//! The render pipelines, all sharing one layout (the scene bind group; the panel adds its
//! image's group), for one colour format and 4× MSAA.

use crate::shaders;

/// MSAA sample count of every pass.
pub(crate) const SAMPLES: u32 = 4;
/// Depth format of every pass.
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Every render pipeline.
pub(crate) struct Pipelines {
    pub skin: wgpu::RenderPipeline,
    pub cut: wgpu::RenderPipeline,
    pub stress: wgpu::RenderPipeline,
    pub wireframe: wgpu::RenderPipeline,
    pub markers: wgpu::RenderPipeline,
    pub tool: wgpu::RenderPipeline,
    pub surface_line: wgpu::RenderPipeline,
    pub panel: wgpu::RenderPipeline,
}

const VEC4: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x4];
const VEC4_1: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![1 => Float32x4];
const VEC3: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];
const INSTANCE: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![1 => Float32x4, 2 => Float32x4];
const POS_NORMAL: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
const POS_NORMAL_COLOUR: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];

/// How one pipeline differs from the others.
struct Spec<'a> {
    layout: &'a wgpu::PipelineLayout,
    shader: &'a str,
    vs: &'a str,
    fs: &'a str,
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    topology: wgpu::PrimitiveTopology,
    depth: (bool, wgpu::CompareFunction),
    blend: Option<wgpu::BlendState>,
}

impl Pipelines {
    pub fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        panel_layout: &wgpu::BindGroupLayout,
        format: wgpu::TextureFormat,
    ) -> Self {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene"),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        });
        let panel_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("panel"),
                bind_group_layouts: &[Some(layout), Some(panel_layout)],
                immediate_size: 0,
            });
        let make = |s: Spec<'_>| {
            let module = shaders::module(device, s.shader);
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(s.shader),
                layout: Some(s.layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(s.vs),
                    compilation_options: Default::default(),
                    buffers: s.buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: s.topology,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(s.depth.0),
                    depth_compare: Some(s.depth.1),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: SAMPLES,
                    mask: !0,
                    alpha_to_coverage_enabled: false,
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(s.fs),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: s.blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let solid = (true, wgpu::CompareFunction::Less);
        let l = &pipeline_layout;
        let tris = wgpu::PrimitiveTopology::TriangleList;
        let vec4 = |attributes| wgpu::VertexBufferLayout {
            array_stride: 16,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes,
        };
        Pipelines {
            skin: make(Spec {
                layout: l,
                shader: "skin",
                vs: "vs",
                fs: "fs",
                buffers: &[Some(vec4(&VEC4)), Some(vec4(&VEC4_1))],
                topology: tris,
                depth: solid,
                blend: None,
            }),
            cut: make(Spec {
                layout: l,
                shader: "tet_faces",
                vs: "vs_cut",
                fs: "fs_cut",
                buffers: &[],
                topology: tris,
                depth: solid,
                blend: None,
            }),
            stress: make(Spec {
                layout: l,
                shader: "tet_faces",
                vs: "vs_surface",
                fs: "fs_stress",
                buffers: &[],
                topology: tris,
                depth: solid,
                blend: None,
            }),
            // X-ray: every live edge, over the surfaces, half transparent.
            wireframe: make(Spec {
                layout: l,
                shader: "wireframe",
                vs: "vs",
                fs: "fs",
                buffers: &[],
                topology: wgpu::PrimitiveTopology::LineList,
                depth: (false, wgpu::CompareFunction::Always),
                blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            }),
            markers: make(Spec {
                layout: l,
                shader: "markers",
                vs: "vs",
                fs: "fs",
                buffers: &[
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 12,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &VEC3,
                    }),
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 32,
                        step_mode: wgpu::VertexStepMode::Instance,
                        attributes: &INSTANCE,
                    }),
                ],
                topology: tris,
                depth: solid,
                blend: None,
            }),
            tool: make(Spec {
                layout: l,
                shader: "tool",
                vs: "vs",
                fs: "fs",
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &POS_NORMAL,
                })],
                topology: tris,
                depth: solid,
                blend: None,
            }),
            // Opaque ribbons lifted off the skin (ribbon.rs), hidden where tissue is nearer.
            surface_line: make(Spec {
                layout: l,
                shader: "surface_line",
                vs: "vs",
                fs: "fs",
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 36,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &POS_NORMAL_COLOUR,
                })],
                topology: tris,
                depth: solid,
                blend: None,
            }),
            // Straight-alpha image after the opaque geometry: depth-tested, not written.
            panel: make(Spec {
                layout: &panel_pipeline_layout,
                shader: "panel",
                vs: "vs",
                fs: "fs",
                buffers: &[],
                topology: tris,
                depth: (false, wgpu::CompareFunction::Less),
                blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            }),
        }
    }
}
