// Prediction (PHYSICS.md §1.2, small-steps loop): v += h g; x_prev = x; x += h v for free
// nodes; grabbed nodes jump to start + the grab's offset at the end of the substep.
// CPU twin: Solver::predict in crates/sim/src/xpbd/solver.rs.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> prev: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> start: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> kind: array<u32>;
@group(0) @binding(6) var<storage, read> grab_offsets: array<vec4<f32>>;
@group(1) @binding(0) var<uniform> S: Step;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= P.node_count) {
        return;
    }
    let p = pos[i];
    prev[i] = p;
    let k = kind[i];
    if (k == KIND_FREE) {
        let v = vel[i].xyz + P.h * P.gravity;
        vel[i] = vec4<f32>(v, 0.0);
        pos[i] = vec4<f32>(p.xyz + P.h * v, p.w);
    } else if (k >= KIND_GRAB0) {
        let off = grab_offsets[S.substep * P.grab_count + (k - KIND_GRAB0)];
        pos[i] = vec4<f32>(start[i].xyz + off.xyz, p.w);
    }
}
