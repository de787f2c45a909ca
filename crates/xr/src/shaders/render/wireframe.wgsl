// Wireframe of the live tets: one line per edge, endpoints pulled from the node positions.

@group(0) @binding(1) var<storage, read> nodes: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> edges: array<vec2<u32>>;

@vertex
fn vs(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let e = edges[vi / 2u];
    var n = e.x;
    if ((vi & 1u) == 1u) { n = e.y; }
    return g.view_proj * vec4<f32>(nodes[n].xyz, 1.0);
}

@fragment
fn fs() -> @location(0) vec4<f32> {
    let c = finish(vec3<f32>(0.02, 0.05, 0.09), ID_LINE);
    if (g.misc.y > 0.5) {
        return c;
    }
    return vec4<f32>(c.rgb, 0.45);
}
