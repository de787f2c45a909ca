// Velocity update and damping (PHYSICS.md §1.2): v = (x - x_prev) / h, scaled by the
// damping factor for free nodes. CPU twin: Solver::update_velocities.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> prev: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> kind: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= P.node_count) {
        return;
    }
    let k = kind[i];
    let d = (pos[i].xyz - prev[i].xyz) * P.inv_h;
    if (k == KIND_FREE) {
        vel[i] = vec4<f32>(d * P.keep, 0.0);
    } else if (k >= KIND_GRAB0) {
        vel[i] = vec4<f32>(d, 0.0);
    } else {
        vel[i] = vec4<f32>(0.0);
    }
}
