// Instanced spheres: tool contact spheres and pinned nodes.

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) colour: vec3<f32>,
};

@vertex
fn vs(
    @location(0) unit: vec3<f32>,
    @location(1) centre_radius: vec4<f32>,
    @location(2) colour: vec4<f32>,
) -> VsOut {
    let p = centre_radius.xyz + unit * centre_radius.w;
    var out: VsOut;
    out.clip = g.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    out.normal = unit;
    out.colour = colour.rgb;
    return out;
}

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {
    let m = Material(in.colour, 0.5, 0.04, 0.0, vec3<f32>(1.0));
    return finish(shade(m, normalize(in.normal), in.world), ID_MARKER);
}
