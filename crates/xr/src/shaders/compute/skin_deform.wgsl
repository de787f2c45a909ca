// Skin deformation (compute): each skin vertex is the barycentric combination of its
// tet's four node positions (PHYSICS.md §1.4 embedding), every frame.

struct Embedding {
    nodes: vec4<u32>,
    bary: vec4<f32>,
};

@group(0) @binding(0) var<storage, read> node_pos: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> embedding: array<Embedding>;
@group(0) @binding(2) var<storage, read_write> skin_pos: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if (i >= arrayLength(&embedding)) {
        return;
    }
    let e = embedding[i];
    let p = e.bary.x * node_pos[e.nodes.x].xyz
        + e.bary.y * node_pos[e.nodes.y].xyz
        + e.bary.z * node_pos[e.nodes.z].xyz
        + e.bary.w * node_pos[e.nodes.w].xyz;
    skin_pos[i] = vec4<f32>(p, 1.0);
}
