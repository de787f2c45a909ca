//! Scenes: RON files in `config/` that say what to simulate (mesh, skin, material, pins,
//! grabs, solver settings, cutting, duration).

mod build;
pub mod built_in;
mod default_scheme;
pub mod hand_tool;
mod load;
mod localisation;
mod material;
pub mod method;
mod model;
mod tool;

pub use build::raw_mesh;
pub use build::{BuiltScene, SceneTool, ToolDriver, build_scene, build_scene_driven};
pub use default_scheme::default_scheme;
pub use load::{SceneError, load_materials, load_scene, locate, parse_materials, parse_scene};
pub use localisation::Localisation;
pub use material::scene_material;
pub use method::Method;
pub use model::{
    HoldSpec, IndenterSpec, MassSpringScene, ModelChoice, RegionSelect, RegionSpec, RheologyScene,
    StrokeSpec,
};
pub use tool::{ToolSpec, load_tool_beside};

use glam::{UVec3, Vec3};
use incise_sim::Material;
use incise_sim::generate::IntestineParams;
use incise_sim::selection::NodeSelection;
use incise_sim::xpbd::SolverParams;
use serde::Deserialize;

/// One simulation scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Short name used in reports.
    pub name: String,
    /// Where the tet mesh comes from.
    pub mesh: MeshSource,
    /// The rendered surface embedded in the tets.
    #[serde(default)]
    pub skin: SkinSource,
    /// Tissue material: a preset name from `config/materials.ron` or explicit values.
    /// Required by the `Xpbd` and `MassSpring` models; a `Rheology` model names its own
    /// materials (per region) and must leave this out.
    #[serde(default)]
    pub material: MaterialChoice,
    /// Node sets fixed in place.
    #[serde(default)]
    pub pins: Vec<NodeSelection>,
    /// Scripted grabs that pull node sets along paths.
    #[serde(default)]
    pub grabs: Vec<GrabSpec>,
    /// Solver settings (scheme, dt, substeps, gravity, damping …); an Xpbd-model scene
    /// whose file names no `scheme` runs `Newton(())` (`default_scheme`).
    #[serde(default)]
    pub solver: SolverParams,
    /// Stress-based cutting; absent = no cutting.
    #[serde(default)]
    pub cutting: Option<Cutting>,
    /// Simulated duration, s.
    pub duration: f32,
    /// Simulation model: `Xpbd` (default), `MassSpring(...)` (PHYSICS.md §2) or
    /// `Rheology(...)` (PHYSICS.md §3).
    #[serde(default)]
    pub model: ModelChoice,
    /// The scalpel (PHYSICS.md §1.5): `Some((file: "tools/scalpel_10.ron"))`.
    #[serde(default)]
    pub tool: Option<ToolSpec>,
    /// What drives the scalpel: `Some(File("strokes/x.ron"))` or `Some(Incision(...))`.
    #[serde(default)]
    pub stroke: Option<incise_scalpel::ToolStroke>,
}

impl Scene {
    /// Frames the scene runs at `frame_dt` s a frame: its duration, rounded, at least one.
    pub fn frame_count(&self, frame_dt: f64) -> u64 {
        (self.duration as f64 / frame_dt).round().max(1.0) as u64
    }
}

/// Where a tet mesh comes from.
#[derive(Debug, Clone, Deserialize)]
pub enum MeshSource {
    /// A mesh file (.node/.ele, .msh, .vtk, .vtu), relative to the scene file.
    File {
        /// Path to the file.
        path: String,
        /// Length unit of the file's coordinates.
        #[serde(default)]
        units: Units,
    },
    /// A procedural generator.
    Generate(Generator),
}

/// Procedural meshes (metres).
#[derive(Debug, Clone, Deserialize)]
pub enum Generator {
    /// The Nakao 2003 plate, 16 × 16 × 0.4 cm.
    Plate,
    /// The torso-like chest wall + heart of the Nakao chest experiment (17,582 nodes).
    Chest,
    /// A curved thick-walled tube with a lumen; `()` for the ≈34k-tet default.
    Intestine(#[serde(default)] IntestineParams),
    /// A box from `min` with edge lengths `size`, split into `cells` hexes (6 tets each).
    Block {
        /// Lower corner, m.
        min: Vec3,
        /// Edge lengths, m.
        size: Vec3,
        /// Hex cells along x, y, z.
        cells: UVec3,
    },
    /// A beam along +x from the origin, centred in y and z.
    Beam {
        /// Length along x, m.
        length: f32,
        /// Width along y, m.
        width: f32,
        /// Height along z, m.
        height: f32,
        /// Hex cells along x, y, z.
        cells: UVec3,
    },
}

/// Length units of mesh files; coordinates are converted to metres on load.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
pub enum Units {
    /// Metres (no conversion).
    #[default]
    Meters,
    /// Centimetres.
    Centimeters,
    /// Millimetres.
    Millimeters,
}

impl Units {
    /// Metres per unit.
    pub fn scale(self) -> f32 {
        match self {
            Units::Meters => 1.0,
            Units::Centimeters => 0.01,
            Units::Millimeters => 0.001,
        }
    }
}

/// The surface drawn over the tets.
#[derive(Debug, Clone, Default, Deserialize)]
pub enum SkinSource {
    /// The generator's fine surface if it has one, else the tet boundary.
    #[default]
    Auto,
    /// The boundary of the tet mesh.
    Boundary,
    /// An OBJ triangle surface, relative to the scene file.
    Obj {
        /// Path to the OBJ file.
        path: String,
        /// Length unit of its coordinates.
        #[serde(default)]
        units: Units,
    },
}

/// A material by preset name or by value.
#[derive(Debug, Clone, Default, Deserialize)]
pub enum MaterialChoice {
    /// Not given in the scene (allowed for `Rheology` models only).
    #[default]
    Unset,
    /// A key of `config/materials.ron`.
    Preset(String),
    /// Explicit values.
    Custom(Material),
}

/// A scripted grab (virtual forceps).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrabSpec {
    /// Which nodes are held.
    pub nodes: NodeSelection,
    /// Displacement waypoints from the start position, m.
    pub path: Vec<Vec3>,
    /// Speed along the path, m/s.
    pub speed: f32,
    /// Time the pull starts, s.
    #[serde(default)]
    pub start: f32,
}

/// Stress-based cutting settings (PHYSICS.md §1.4).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cutting {
    /// von Mises stress above which a tet is released, Pa.
    pub von_mises_threshold: f32,
}
