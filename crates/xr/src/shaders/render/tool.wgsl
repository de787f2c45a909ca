// The tool mesh (blade and handle) placed by the tool transform, in brushed steel.

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

@vertex
fn vs(@location(0) pos: vec3<f32>, @location(1) nrm: vec3<f32>) -> VsOut {
    let w = g.tool_model * vec4<f32>(pos, 1.0);
    var out: VsOut;
    out.clip = g.view_proj * w;
    out.world = w.xyz;
    // The tool transform is rigid (rotation + translation), so it maps normals too.
    out.normal = (g.tool_model * vec4<f32>(nrm, 0.0)).xyz;
    return out;
}

@fragment
fn fs(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    var n = normalize(in.normal);
    if (!front) { n = -n; }
    let steel = Material(vec3<f32>(0.55, 0.57, 0.60), 0.28, 0.56, 0.0, vec3<f32>(1.0));
    return finish(shade(steel, n, in.world), ID_TOOL);
}
