// The conjugate gradient of a Newton iteration on the device (Shewchuk 1994, B3; truncated
// at non-positive curvature as in Nocedal & Wright 2006, Alg. 7.1), preconditioned by
// z = D^-1 r + P A_c^-1 P^T r: block Jacobi plus the coarse grid, whose inverse the host
// computes from its Cholesky factor and uploads (docs/physics-notes.md, "The implicit
// scheme on the GPU"). The solve's scalars live in `scratch`: `product` (newton_tets.wgsl)
// decides beta and the stop, `step_restrict` (one workgroup) alpha and the curvature; the
// other kernels read what they wrote, so every thread uses the same values and nothing is
// read back per iteration. CPU twin: crates/sim/src/implicit/pcg.rs and TwoLevel::apply in
// implicit/workspace.rs.
//
// coarse_map: per fine node 8 coarse ids then their 8 weights (f32 bits); from
// NW.transpose_at, per coarse node the start of its (fine node, weight bits) pairs, then
// one past the last.

@group(0) @binding(0) var<uniform> NW: Newton;
@group(0) @binding(1) var<storage, read_write> vecs: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> kind: array<u32>;
@group(0) @binding(3) var<storage, read> coarse_map: array<u32>;
@group(0) @binding(4) var<storage, read_write> coarse_vec: array<f32>;
@group(0) @binding(5) var<storage, read> ainv: array<f32>;
@group(0) @binding(6) var<storage, read_write> scratch: array<f32>;

// The sum of `count` partial sums from `at`, by one workgroup of 256 threads; every thread
// gets it.
fn sum_partials(l: u32, at: u32, count: u32) -> f32 {
    var v = 0.0;
    for (var k = l; k < count; k += 256u) {
        v += scratch[at + k];
    }
    red[l] = v;
    workgroupBarrier();
    for (var s = 128u; s > 0u; s = s >> 1u) {
        if (l < s) {
            red[l] = red[l] + red[l + s];
        }
        workgroupBarrier();
    }
    let total = red[0];
    workgroupBarrier();
    return total;
}

fn stopped() -> bool {
    let st = at_state();
    return scratch[st + S_STOP] != 0.0 || scratch[st + S_NEG] != 0.0;
}

// P^T (r - alpha A p) for coarse node c, from its fine nodes in order.
fn restrict_node(c: u32, alpha: f32) {
    var sum = vec3<f32>(0.0);
    for (var k = coarse_map[NW.transpose_at + c]; k < coarse_map[NW.transpose_at + c + 1u]; k += 2u) {
        let i = coarse_map[k];
        let r = vecs[vi(V_R, i)].xyz - alpha * vecs[vi(V_AP, i)].xyz;
        sum += bitcast<f32>(coarse_map[k + 1u]) * r;
    }
    coarse_vec[3u * c] = sum.x;
    coarse_vec[3u * c + 1u] = sum.y;
    coarse_vec[3u * c + 2u] = sum.z;
}

// z = D^-1 r + P x_c at a free node, zero at a fixed one.
fn precondition(i: u32, r: vec3<f32>) -> vec3<f32> {
    if (kind[i] != KIND_FREE) {
        return vec3<f32>(0.0);
    }
    let d = mat3x3<f32>(vecs[vi(V_DINV, i)].xyz, vecs[vi(V_DINV + 1u, i)].xyz, vecs[vi(V_DINV + 2u, i)].xyz);
    var z = d * r;
    let xc = 3u * NW.coarse_nodes;
    for (var k = 0u; k < 8u; k++) {
        let id = coarse_map[16u * i + k];
        let w = bitcast<f32>(coarse_map[16u * i + 8u + k]);
        z += w * vec3<f32>(coarse_vec[xc + 3u * id], coarse_vec[xc + 3u * id + 1u], coarse_vec[xc + 3u * id + 2u]);
    }
    return z;
}

// A solve's start (one workgroup): the state cleared, and P^T r for r = -grad G.
@compute @workgroup_size(256)
fn restrict_init(@builtin(local_invocation_index) l: u32) {
    let st = at_state();
    if (l < 8u) {
        scratch[st + l] = 0.0;
    }
    for (var c = l; c < NW.coarse_nodes; c += 256u) {
        var sum = vec3<f32>(0.0);
        for (var k = coarse_map[NW.transpose_at + c]; k < coarse_map[NW.transpose_at + c + 1u]; k += 2u) {
            let i = coarse_map[k];
            sum -= bitcast<f32>(coarse_map[k + 1u]) * vecs[vi(V_G, i)].xyz;
        }
        coarse_vec[3u * c] = sum.x;
        coarse_vec[3u * c + 1u] = sum.y;
        coarse_vec[3u * c + 2u] = sum.z;
    }
}

// x_c = A_c^-1 r_c, one thread per row (A_c^-1 is symmetric: read by columns, which
// neighbouring threads read side by side).
@compute @workgroup_size(64)
fn coarse_solve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rows = 3u * NW.coarse_nodes;
    let row = gid.x;
    if (row >= rows || stopped()) {
        return;
    }
    var sum = 0.0;
    for (var c = 0u; c < rows; c++) {
        sum += ainv[c * rows + row] * coarse_vec[c];
    }
    coarse_vec[rows + row] = sum;
}

// A solve's first residual r = -grad G, x = 0, p = 0, z = M^-1 r, partial sums of r . z.
@compute @workgroup_size(64)
fn precondition_init(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    var rz = 0.0;
    if (i < NW.node_count) {
        let r = -vecs[vi(V_G, i)].xyz;
        let z = precondition(i, r);
        vecs[vi(V_R, i)] = vec4<f32>(r, 0.0);
        vecs[vi(V_X, i)] = vec4<f32>(0.0);
        vecs[vi(V_P, i)] = vec4<f32>(0.0);
        vecs[vi(V_Z, i)] = vec4<f32>(z, 0.0);
        rz = dot(r, z);
    }
    let total = sum64(l, rz);
    if (l == 0u) {
        scratch[at_rz() + wg.x] = total;
    }
}

// After the product (one workgroup): p . A p reduced; at p . A p <= 0 the solve stops
// (negative curvature), else alpha = r.z / p.Ap and P^T (r - alpha A p) for the
// preconditioner.
@compute @workgroup_size(256)
fn step_restrict(@builtin(local_invocation_index) l: u32) {
    let pap = sum_partials(l, at_pap(), NW.node_groups);
    let st = at_state();
    if (stopped()) {
        return;
    }
    if (pap <= 0.0) {
        if (l == 0u) {
            scratch[st + S_NEG] = 1.0;
        }
        return;
    }
    let alpha = scratch[st + S_RZ] / pap;
    if (l == 0u) {
        scratch[st + S_ALPHA] = alpha;
    }
    for (var c = l; c < NW.coarse_nodes; c += 256u) {
        restrict_node(c, alpha);
    }
}

// x += alpha p, r -= alpha A p, z = M^-1 r, partial sums of r . z. At negative curvature
// on the first product the direction is p itself (the preconditioned gradient, a descent
// direction), as the CPU's.
@compute @workgroup_size(64)
fn update(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    let st = at_state();
    var rz = 0.0;
    if (i < NW.node_count && scratch[st + S_STOP] == 0.0) {
        if (scratch[st + S_NEG] != 0.0) {
            if (scratch[st + S_PRODUCTS] == 1.0) {
                vecs[vi(V_X, i)] = vecs[vi(V_P, i)];
            }
        } else {
            let alpha = scratch[st + S_ALPHA];
            let p = vecs[vi(V_P, i)].xyz;
            vecs[vi(V_X, i)] = vec4<f32>(vecs[vi(V_X, i)].xyz + alpha * p, 0.0);
            let r = vecs[vi(V_R, i)].xyz - alpha * vecs[vi(V_AP, i)].xyz;
            let z = precondition(i, r);
            vecs[vi(V_R, i)] = vec4<f32>(r, 0.0);
            vecs[vi(V_Z, i)] = vec4<f32>(z, 0.0);
            rz = dot(r, z);
        }
    }
    let total = sum64(l, rz);
    if (l == 0u) {
        scratch[at_rz() + wg.x] = total;
    }
}
