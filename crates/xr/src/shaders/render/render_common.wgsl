// Shared by every render shader (prepended by crates/xr/src/shaders.rs): the per-view
// globals and the physically-based-lite tissue shading (one key light, a hemisphere
// ambient as the image-based-lighting stand-in, wrap diffuse for subsurface scattering,
// GGX specular for wet surfaces).

struct Globals {
    view_proj: mat4x4<f32>,
    tool_model: mat4x4<f32>,
    // Local unit square → world of the panel quad.
    panel_model: mat4x4<f32>,
    // xyz: camera position, w: unused.
    eye: vec4<f32>,
    // xyz: unit direction towards the key light, w: its intensity.
    light: vec4<f32>,
    // x: 1 / stress colour-scale maximum (1/Pa), y: shading mode (0 lit, 1 material ids),
    // z: exposure, w: unused.
    misc: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;

struct Material {
    albedo: vec3<f32>,
    roughness: f32,
    // Normal-incidence Fresnel reflectance.
    f0: f32,
    // Wrap-lighting amount (0: Lambert; larger: light bleeds past the terminator).
    wrap: f32,
    // Colour that scattered light takes on under the surface.
    scatter: vec3<f32>,
};

const PI: f32 = 3.14159265;

fn ggx_specular(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, roughness: f32, f0: f32) -> f32 {
    let h = normalize(v + l);
    let nl = max(dot(n, l), 0.0);
    let nv = max(dot(n, v), 1e-4);
    let nh = max(dot(n, h), 0.0);
    let a = roughness * roughness;
    let a2 = a * a;
    let d = a2 / (PI * pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
    let k = a * 0.5;
    let vis = 1.0 / ((nl * (1.0 - k) + k) * (nv * (1.0 - k) + k));
    let f = f0 + (1.0 - f0) * pow(1.0 - max(dot(h, v), 0.0), 5.0);
    return d * vis * f * nl * 0.25;
}

// Linear radiance of a surface point with normal `n` (unit, facing the viewer) at `p`.
fn shade(m: Material, n: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let v = normalize(g.eye.xyz - p);
    let l = g.light.xyz;
    let nl = dot(n, l);
    let lambert = max(nl, 0.0);
    let wrapped = max((nl + m.wrap) / (1.0 + m.wrap), 0.0);
    // Light that wrapped past the terminator has travelled through tissue: tint it.
    let diffuse = m.albedo * lambert + m.scatter * m.albedo * (wrapped - lambert);
    let key = g.light.w * (diffuse / PI + vec3<f32>(ggx_specular(n, v, l, m.roughness, m.f0)));
    // Hemisphere ambient: warm room light from above, dark table bounce from below.
    let sky = vec3<f32>(0.36, 0.37, 0.40);
    let ground = vec3<f32>(0.10, 0.07, 0.06);
    let ambient = mix(ground, sky, n.z * 0.5 + 0.5) * m.albedo;
    // A soft environment reflection so wet surfaces keep a sheen away from the key light.
    let fv = m.f0 + (1.0 - m.f0) * pow(1.0 - max(dot(n, v), 0.0), 5.0);
    let env = mix(ground, sky * 1.6, reflect(-v, n).z * 0.5 + 0.5) * fv * (1.0 - m.roughness);
    return key + ambient + env;
}

// Final colour: ACES-fitted tone curve of the exposed radiance (the sRGB target encodes
// it), or the flat material-id colour in id mode.
fn finish(radiance: vec3<f32>, id_colour: vec3<f32>) -> vec4<f32> {
    if (g.misc.y > 0.5) {
        return vec4<f32>(id_colour, 1.0);
    }
    let x = radiance * g.misc.z;
    let c = clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
    return vec4<f32>(c, 1.0);
}

fn skin_material() -> Material {
    return Material(vec3<f32>(0.70, 0.30, 0.26), 0.42, 0.028, 0.5, vec3<f32>(0.95, 0.30, 0.18));
}

// The inside of the organ: darker, redder and glossy (wet).
fn cut_material() -> Material {
    return Material(vec3<f32>(0.50, 0.055, 0.06), 0.16, 0.035, 0.35, vec3<f32>(0.85, 0.12, 0.10));
}

// Material-id colours (id mode): what tests count on screen. Linear values of the sRGB
// bytes in MATERIAL_IDS (crates/xr/src/frame.rs): 0.2158605 encodes as 128.
const ID_SKIN: vec3<f32> = vec3<f32>(0.0, 1.0, 0.0);
const ID_SKIN_BACK: vec3<f32> = vec3<f32>(0.0, 0.0, 1.0);
const ID_CUT: vec3<f32> = vec3<f32>(1.0, 0.0, 0.0);
const ID_STRESS: vec3<f32> = vec3<f32>(1.0, 1.0, 0.0);
const ID_TOOL: vec3<f32> = vec3<f32>(1.0, 0.0, 1.0);
const ID_MARKER: vec3<f32> = vec3<f32>(0.0, 1.0, 1.0);
const ID_LINE: vec3<f32> = vec3<f32>(1.0, 1.0, 1.0);
const ID_PLAN: vec3<f32> = vec3<f32>(1.0, 0.2158605, 0.0);
const ID_PANEL: vec3<f32> = vec3<f32>(0.2158605, 0.0, 1.0);
