//! The WGSL sources of the renderer, in `shaders/render/` and `shaders/compute/` beside
//! this file: render shaders get `render_common.wgsl` (globals and tissue shading)
//! prepended; compute shaders stand alone.

const COMMON: &str = include_str!("shaders/render/render_common.wgsl");

/// Render shaders (each `shaders/render/<name>.wgsl`, with the common part prepended).
pub const RENDER_SHADERS: [&str; 7] = [
    "skin",
    "tet_faces",
    "wireframe",
    "markers",
    "tool",
    "surface_line",
    "panel",
];

/// Compute shaders of the node world positions and the skin deformation (each
/// `shaders/compute/<name>.wgsl`).
pub const COMPUTE_SHADERS: [&str; 3] = ["node_world", "skin_deform", "skin_normals"];

/// Full WGSL source of a renderer shader, or `None` if unknown.
pub fn source(name: &str) -> Option<String> {
    let render = |body: &str| format!("{COMMON}\n{body}");
    Some(match name {
        "skin" => render(include_str!("shaders/render/skin.wgsl")),
        "tet_faces" => render(include_str!("shaders/render/tet_faces.wgsl")),
        "wireframe" => render(include_str!("shaders/render/wireframe.wgsl")),
        "markers" => render(include_str!("shaders/render/markers.wgsl")),
        "tool" => render(include_str!("shaders/render/tool.wgsl")),
        "surface_line" => render(include_str!("shaders/render/surface_line.wgsl")),
        "panel" => render(include_str!("shaders/render/panel.wgsl")),
        "node_world" => include_str!("shaders/compute/node_world.wgsl").to_string(),
        "skin_deform" => include_str!("shaders/compute/skin_deform.wgsl").to_string(),
        "skin_normals" => include_str!("shaders/compute/skin_normals.wgsl").to_string(),
        _ => return None,
    })
}

/// A shader module for `name` (which must be one of [`RENDER_SHADERS`] or
/// [`COMPUTE_SHADERS`]).
pub(crate) fn module(device: &wgpu::Device, name: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(source(name).unwrap_or_default().into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every renderer shader parses and validates with naga, without an adapter.
    #[test]
    fn all_shaders_validate_with_naga() {
        for name in RENDER_SHADERS.iter().chain(&COMPUTE_SHADERS) {
            let src = source(name).unwrap();
            let module = wgpu::naga::front::wgsl::parse_str(&src)
                .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(&src)));
            wgpu::naga::valid::Validator::new(
                wgpu::naga::valid::ValidationFlags::all(),
                wgpu::naga::valid::Capabilities::empty(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(&src)));
        }
        assert!(source("nonexistent").is_none());
    }

    /// The shaders' `ID_*` constants are the linear values of the sRGB bytes that
    /// `MATERIAL_IDS` promises (what tests look for in id-mode images).
    #[test]
    fn id_colours_in_the_shaders_encode_to_the_material_id_bytes() {
        let encode = |c: f32| {
            let s = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0).round() as u8
        };
        for (name, bytes) in crate::frame::MATERIAL_IDS {
            let decl = format!("const ID_{}: vec3<f32> = vec3<f32>(", name.to_uppercase());
            let start = COMMON
                .find(&decl)
                .unwrap_or_else(|| panic!("render_common.wgsl has no `{decl}`"))
                + decl.len();
            let args = &COMMON[start..start + COMMON[start..].find(')').unwrap()];
            let linear: Vec<f32> = args.split(',').map(|v| v.trim().parse().unwrap()).collect();
            let encoded: Vec<u8> = linear.iter().map(|&c| encode(c)).collect();
            assert_eq!(encoded, bytes, "ID_{} = {linear:?}", name.to_uppercase());
        }
    }
}
