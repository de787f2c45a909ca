// The implicit scheme's per-node kernels, one thread per node: the step's first iterate,
// the gradient and inverted diagonal blocks gathered from the tets' corners, the inertia
// term alone, the line search's trial point, and the gather of the conjugate gradient's
// product. Each writes one partial sum per workgroup of what the host or the next kernel
// reduces. CPU twin: NewtonWorkspace::solve and Hessian::{gather_gradient,
// gather_products, total} in crates/sim/src/implicit/workspace.rs.

@group(0) @binding(0) var<uniform> NW: Newton;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> vecs: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> kind: array<u32>;
@group(0) @binding(4) var<storage, read> tet_out: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> inc: array<u32>;
@group(0) @binding(6) var<storage, read_write> scratch: array<f32>;
// The contact kernel's per-node push (contact.wgsl): `reaction` books the held nodes'
// (w: 1 until `unload` has run after the step).
@group(0) @binding(7) var<storage, read_write> push: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> live: array<u32>;

fn is_free(i: u32) -> bool {
    return kind[i] == KIND_FREE;
}

// The step's start, after the prediction (PHYSICS.md §1.2's small-steps loop, one implicit
// step long): y = u + h v + h^2 g (what `pos` holds), and the
// first iterate u + h v, without this step's h^2 g (docs/physics-notes.md, "The initial
// iterate").
@compute @workgroup_size(64)
fn start(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= NW.node_count) {
        return;
    }
    var p = pos[i];
    vecs[vi(V_Y, i)] = p;
    if (is_free(i)) {
        p = vec4<f32>(p.xyz - NW.fall, p.w);
        pos[i] = p;
    }
    vecs[vi(V_TRIAL, i)] = p;
}

// A further solve of the same step (the nodes the last one carried into the tool now
// held): its first point is the iterate as the contact left it.
@compute @workgroup_size(64)
fn resume(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i < NW.node_count) {
        vecs[vi(V_TRIAL, i)] = pos[i];
    }
}

// The force that held each node the tool held through the solve, grad G there (CPU twin:
// NewtonWorkspace::reaction), booked as the tool's push h^2 f (contact.wgsl's m dx).
@compute @workgroup_size(64)
fn reaction(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= NW.node_count || kind[i] != KIND_HELD) {
        return;
    }
    let m = vecs[vi(V_MASS, i)].x * NW.inv_h2;
    var g = (pos[i].xyz - vecs[vi(V_Y, i)].xyz) * m;
    for (var k = inc[i]; k < inc[i + 1u]; k++) {
        let e = inc[k];
        g += tet_out[(e >> 2u) * TET_STRIDE + FORCE + (e & 3u)].xyz;
    }
    push[i] = vec4<f32>(push[i].xyz + g / NW.inv_h2, 1.0);
}

// Failed tissue carries no load (CPU twin: Solver::unload_released), after the step's
// release check: a node `reaction` booked gives back the corner forces of its tets the
// check switched off (a tet released before the step evaluated to zero), and its mark
// clears.
@compute @workgroup_size(64)
fn unload(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= NW.node_count || push[i].w == 0.0) {
        return;
    }
    var g = vec3<f32>(0.0);
    for (var k = inc[i]; k < inc[i + 1u]; k++) {
        let e = inc[k];
        if (live[e >> 2u] == 0u) {
            g += tet_out[(e >> 2u) * TET_STRIDE + FORCE + (e & 3u)].xyz;
        }
    }
    push[i] = vec4<f32>(push[i].xyz - g / NW.inv_h2, 0.0);
}

// grad G = M/h^2 (u - y) + sum of the corner forces, and the inverse of
// M/h^2 I + sum of the corner blocks, at the trial point (zero at fixed nodes); partial
// sums of |grad G|^2 and of m |u - y|^2 (the inertia, free nodes).
@compute @workgroup_size(64)
fn gather(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    var g2 = 0.0;
    var inertia = 0.0;
    if (i < NW.node_count) {
        var g = vec3<f32>(0.0);
        var inv = mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
        if (is_free(i)) {
            let mass = vecs[vi(V_MASS, i)].x;
            let m = mass * NW.inv_h2;
            let du = vecs[vi(V_TRIAL, i)].xyz - vecs[vi(V_Y, i)].xyz;
            g = du * m;
            var d = IDENTITY3 * m;
            for (var k = inc[i]; k < inc[i + 1u]; k++) {
                let e = inc[k];
                let o = (e >> 2u) * TET_STRIDE;
                let a = e & 3u;
                g += tet_out[o + FORCE + a].xyz;
                d += sym_block(tet_out[o + DIAG + 2u * a], tet_out[o + DIAG + 2u * a + 1u]);
            }
            // The inverse as glam's Mat3::inverse forms it.
            let c = cofactor(d);
            inv = transpose(c) * (1.0 / dot(d[2], c[2]));
            g2 = dot(g, g);
            inertia = mass * dot(du, du);
        }
        vecs[vi(V_G, i)] = vec4<f32>(g, 0.0);
        vecs[vi(V_DINV, i)] = vec4<f32>(inv[0], 0.0);
        vecs[vi(V_DINV + 1u, i)] = vec4<f32>(inv[1], 0.0);
        vecs[vi(V_DINV + 2u, i)] = vec4<f32>(inv[2], 0.0);
    }
    let g2_total = sum64(l, g2);
    let inertia_total = sum64(l, inertia);
    if (l == 0u) {
        scratch[at_grad2() + wg.x] = g2_total;
        scratch[at_inertia() + wg.x] = inertia_total;
    }
}

// Partial sums of m |u - y|^2 at the trial point (free nodes): the line search's halved
// steps.
@compute @workgroup_size(64)
fn inertia(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    var e = 0.0;
    if (i < NW.node_count && is_free(i)) {
        let du = vecs[vi(V_TRIAL, i)].xyz - vecs[vi(V_Y, i)].xyz;
        e = vecs[vi(V_MASS, i)].x * dot(du, du);
    }
    let total = sum64(l, e);
    if (l == 0u) {
        scratch[at_inertia() + wg.x] = total;
    }
}

// The line search's trial point u + alpha d, partial sums of the slope grad G . d, and
// per workgroup the largest |d|^2 of a free node (the step stop's reach).
@compute @workgroup_size(64)
fn trial(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    var slope = 0.0;
    var reach2 = 0.0;
    if (i < NW.node_count) {
        let d = vecs[vi(V_X, i)].xyz;
        let p = pos[i];
        vecs[vi(V_TRIAL, i)] = vec4<f32>(p.xyz + NW.alpha * d, p.w);
        slope = dot(vecs[vi(V_G, i)].xyz, d);
        if (is_free(i)) {
            reach2 = dot(d, d);
        }
    }
    let total = sum64(l, slope);
    let top = max64(l, reach2);
    if (l == 0u) {
        scratch[at_slope() + wg.x] = total;
        scratch[at_reach() + wg.x] = top;
    }
}

// The conjugate gradient's product, per node: p = z + beta p (stored), then
// A p = M/h^2 p + the sum of the corner forces (zero at fixed nodes), and partial sums of
// p . A p; workgroup 0 books the product and its r . z.
@compute @workgroup_size(64)
fn gather_product(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let i = gid.x;
    let st = at_state();
    var pap = 0.0;
    let running = scratch[st + S_STOP] == 0.0 && scratch[st + S_NEG] == 0.0;
    if (running && wg.x == 0u && l == 0u) {
        scratch[st + S_RZ] = scratch[st + S_RZ_NEXT];
        scratch[st + S_PRODUCTS] = scratch[st + S_PRODUCTS] + 1.0;
    }
    if (i < NW.node_count && running) {
        let p = vecs[vi(V_Z, i)].xyz + scratch[st + S_BETA] * vecs[vi(V_P, i)].xyz;
        vecs[vi(V_P, i)] = vec4<f32>(p, 0.0);
        var ap = vec3<f32>(0.0);
        if (is_free(i)) {
            ap = p * (vecs[vi(V_MASS, i)].x * NW.inv_h2);
            for (var k = inc[i]; k < inc[i + 1u]; k++) {
                let e = inc[k];
                ap += tet_out[(e >> 2u) * TET_STRIDE + PRODUCT + (e & 3u)].xyz;
            }
        }
        vecs[vi(V_AP, i)] = vec4<f32>(ap, 0.0);
        pap = dot(p, ap);
    }
    let total = sum64(l, pap);
    if (l == 0u) {
        scratch[at_pap() + wg.x] = total;
    }
}
