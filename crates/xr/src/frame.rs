//! What the renderer is given each frame: the body's state and the display settings.

use glam::{Mat4, Vec3};
use incise_sim::TetMesh;
use incise_sim::cutting::CutState;

/// The simulated body as of the last frame.
#[derive(Clone, Copy)]
pub struct BodyState<'a> {
    /// Node positions on the host (the CPU solver's, or the GPU solver's mirror), m.
    pub positions: &'a [Vec3],
    /// The nodes' displacements from their rest positions already on the render device
    /// (`vec4<f32>` per node, xyz = `u`, as the GPU solver keeps them): the renderer adds
    /// the rest positions on the device instead of uploading `positions`.
    pub device_displacements: Option<&'a wgpu::Buffer>,
    /// Live tets, visible faces and their changes.
    pub cut: &'a CutState,
    /// The heat map's value per tet (mesh order), in the body's own quantity (an XPBD
    /// body's von Mises stress, Pa; a Nakao body's tension; a rheology body's strain).
    pub heat: &'a [f32],
    /// Pinned nodes (drawn by the pinned-nodes overlay).
    pub pinned: &'a [u32],
}

/// An uncut, unstressed body of a mesh, nothing pinned: with any node positions it makes
/// a [`BodyState`] (benchmarks, tests, pictures of a mesh as it is).
pub struct UncutBody {
    cut: CutState,
    heat: Vec<f32>,
}

impl UncutBody {
    /// Every tet of `mesh` live, zero stress.
    pub fn new(mesh: &TetMesh) -> Self {
        UncutBody {
            cut: CutState::new(mesh),
            heat: vec![0.0; mesh.tet_count()],
        }
    }

    /// The body with its nodes at `positions` (host), m.
    pub fn state<'a>(&'a self, positions: &'a [Vec3]) -> BodyState<'a> {
        BodyState {
            positions,
            device_displacements: None,
            cut: &self.cut,
            heat: &self.heat,
            pinned: &[],
        }
    }
}

/// Which overlays are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Overlays {
    /// von Mises heat map on the tet surface (replaces the skin).
    pub stress: bool,
    /// Edges of the live tets.
    pub wireframe: bool,
    /// The tool's contact spheres.
    pub tool_spheres: bool,
    /// Pinned nodes.
    pub pinned: bool,
}

/// How surfaces are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShadingMode {
    /// Tissue shading (the normal picture).
    #[default]
    Lit,
    /// Flat colours per material (skin, skin back, cut surface, stress, tool, markers,
    /// wireframe lines, surface lines, the panel; see [`MATERIAL_IDS`]), for tests and
    /// picking.
    MaterialIds,
}

/// The flat colours of [`ShadingMode::MaterialIds`], by material name, as the bytes of an
/// sRGB image (the `ID_*` constants of `shaders/render/render_common.wgsl` are their linear values).
pub const MATERIAL_IDS: [(&str, [u8; 3]); 9] = [
    ("skin", [0, 255, 0]),
    ("skin_back", [0, 0, 255]),
    ("cut", [255, 0, 0]),
    ("stress", [255, 255, 0]),
    ("tool", [255, 0, 255]),
    ("marker", [0, 255, 255]),
    ("line", [255, 255, 255]),
    ("plan", [255, 128, 0]),
    ("panel", [128, 0, 255]),
];

/// A line drawn on the tissue surface, e.g. a planned incision (deformed positions).
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceLine {
    /// Points along the line, world m.
    pub points: Vec<Vec3>,
    /// Outward surface normal at each point (same length as `points`).
    pub normals: Vec<Vec3>,
    /// Width of the drawn band, m.
    pub width: f32,
    /// Colour, linear RGB.
    pub colour: [f32; 3],
}

/// The scalpel (or stand-in) as drawn.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ToolState {
    /// Tool mesh placement (rigid: rotation and translation), tool frame → world; `None`
    /// hides the mesh. The mesh is the stand-in blade unless
    /// [`crate::Renderer::set_tool_mesh`] gave another.
    pub transform: Option<Mat4>,
    /// Contact spheres (centre, radius), m: drawn by the tool-spheres overlay.
    pub spheres: Vec<(Vec3, f32)>,
}

/// Display settings of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    /// Overlays drawn.
    pub overlays: Overlays,
    /// Shading mode.
    pub shading: ShadingMode,
    /// Stress at the top of the heat-map colour scale, Pa (the cut threshold, usually).
    pub stress_max: f32,
    /// The tool.
    pub tool: ToolState,
    /// Background colour (linear RGB).
    pub background: [f64; 3],
    /// Background alpha: 1 opaque; 0 lets a layer behind show through (XR passthrough).
    pub background_alpha: f64,
    /// Exposure applied before tone mapping.
    pub exposure: f32,
    /// Lines drawn on the tissue surface.
    pub lines: Vec<SurfaceLine>,
    /// World placement of the panel quad: the unit square [-0.5,0.5]² of its local xy
    /// plane (image up = +y, image right = +x, seen from +z), scaled/rotated/translated by
    /// this; `None` hides it. The image comes from [`crate::Renderer::set_panel_image`]
    /// (no image: nothing drawn).
    pub panel: Option<Mat4>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            overlays: Overlays::default(),
            shading: ShadingMode::Lit,
            stress_max: 1e4,
            tool: ToolState::default(),
            background: [0.020, 0.024, 0.032],
            background_alpha: 1.0,
            exposure: 1.0,
            lines: Vec::new(),
            panel: None,
        }
    }
}
