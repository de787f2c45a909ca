// Lines on the tissue surface (planned incisions): ribbons built on the host from the
// deformed points (crates/xr/src/ribbon.rs), already lifted off the skin, drawn in their
// own ink colour.

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) colour: vec3<f32>,
};

@vertex
fn vs(
    @location(0) pos: vec3<f32>,
    @location(1) nrm: vec3<f32>,
    @location(2) colour: vec3<f32>,
) -> VsOut {
    var out: VsOut;
    out.clip = g.view_proj * vec4<f32>(pos, 1.0);
    out.normal = nrm;
    out.colour = colour;
    return out;
}

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {
    if (g.misc.y > 0.5) {
        return vec4<f32>(ID_PLAN, 1.0);
    }
    // Unlit ink, not tone mapped: its given colour, a touch darker where the surface
    // turns away from the key light so the line keeps the organ's shape.
    let k = 0.85 + 0.15 * max(dot(normalize(in.normal), g.light.xyz), 0.0);
    return vec4<f32>(clamp(in.colour * k, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
