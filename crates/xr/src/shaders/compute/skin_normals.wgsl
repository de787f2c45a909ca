// Skin normals (compute): each vertex gathers the area-weighted normals of its triangles
// (vertex → triangle adjacency, no atomics), after skin_deform.

@group(0) @binding(0) var<storage, read> skin_pos: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> triangles: array<u32>;
@group(0) @binding(2) var<storage, read> adjacency_offsets: array<u32>;
@group(0) @binding(3) var<storage, read> adjacency: array<u32>;
@group(0) @binding(4) var<storage, read_write> skin_normal: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if (i >= arrayLength(&skin_normal)) {
        return;
    }
    var n = vec3<f32>(0.0);
    for (var k = adjacency_offsets[i]; k < adjacency_offsets[i + 1u]; k++) {
        let t = adjacency[k] * 3u;
        let a = skin_pos[triangles[t]].xyz;
        let b = skin_pos[triangles[t + 1u]].xyz;
        let c = skin_pos[triangles[t + 2u]].xyz;
        n += cross(b - a, c - a);
    }
    let len = length(n);
    if (len > 0.0) {
        n = n / len;
    } else {
        n = vec3<f32>(0.0, 0.0, 1.0);
    }
    skin_normal[i] = vec4<f32>(n, 0.0);
}
