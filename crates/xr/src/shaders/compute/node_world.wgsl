// World positions of the body's nodes from the solver's device state (compute): the GPU
// solver keeps displacements u = x − X (docs/physics-notes.md, "State is displacement"),
// the render shaders read world positions x = X + u.

@group(0) @binding(0) var<storage, read> rest: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> displacement: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> world: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if (i >= arrayLength(&rest)) {
        return;
    }
    world[i] = vec4<f32>(rest[i].xyz + displacement[i].xyz, 1.0);
}
