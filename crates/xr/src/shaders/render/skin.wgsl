// The skin: deformed positions and normals come from the skin_deform/skin_normals passes
// as vertex buffers; front faces are serosa, back faces (seen through a cut) the inside.

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

@vertex
fn vs(@location(0) pos: vec4<f32>, @location(1) nrm: vec4<f32>) -> VsOut {
    var out: VsOut;
    out.clip = g.view_proj * vec4<f32>(pos.xyz, 1.0);
    out.world = pos.xyz;
    out.normal = nrm.xyz;
    return out;
}

@fragment
fn fs(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    var n = normalize(in.normal);
    if (!front) {
        let inside = cut_material();
        return finish(shade(inside, -n, in.world) * 0.6, ID_SKIN_BACK);
    }
    return finish(shade(skin_material(), n, in.world), ID_SKIN);
}
