// The panel quad (an exercise's result card): the unit square of its local xy plane,
// placed by g.panel_model, showing the app's image unlit with its straight alpha.

@group(1) @binding(0) var panel_image: texture_2d<f32>;
@group(1) @binding(1) var panel_sampler: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs(@builtin(vertex_index) vi: u32) -> VsOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-0.5, -0.5), vec2<f32>(0.5, -0.5), vec2<f32>(0.5, 0.5),
        vec2<f32>(-0.5, -0.5), vec2<f32>(0.5, 0.5), vec2<f32>(-0.5, 0.5),
    );
    let c = corners[vi];
    var out: VsOut;
    out.clip = g.view_proj * g.panel_model * vec4<f32>(c, 0.0, 1.0);
    // Image right = +x, image up = +y; texture rows run top first.
    out.uv = vec2<f32>(c.x + 0.5, 0.5 - c.y);
    return out;
}

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {
    let c = textureSample(panel_image, panel_sampler, in.uv);
    if (g.misc.y > 0.5) {
        // Id mode: the panel's flat colour where the image is at least half opaque.
        if (c.a < 0.5) {
            discard;
        }
        return vec4<f32>(ID_PANEL, 1.0);
    }
    return c;
}
