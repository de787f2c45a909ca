// The implicit scheme's per-tet kernels, one thread per tet slot (colour order, as the XPBD
// kernels'): the full evaluation at the trial point (energy, corner forces, diagonal
// blocks, tangent), the energy alone (the line search's halved steps), and the Hessian
// product's corner forces. CPU twin: Hessian::evaluate, Hessian::energy and
// Hessian::apply in crates/sim/src/implicit/hessian.rs.

@group(0) @binding(0) var<uniform> NW: Newton;
@group(0) @binding(1) var<storage, read> tets: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read> rest: array<TetRest>;
@group(0) @binding(3) var<storage, read> live: array<u32>;
@group(0) @binding(4) var<storage, read> vecs: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> tet_out: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> scratch: array<f32>;

fn strain_at(slot: u32) -> Strain {
    let idx = tets[slot];
    let u0 = vecs[vi(V_TRIAL, idx.x)].xyz;
    let u1 = vecs[vi(V_TRIAL, idx.y)].xyz;
    let u2 = vecs[vi(V_TRIAL, idx.z)].xyz;
    let u3 = vecs[vi(V_TRIAL, idx.w)].xyz;
    return strain_of(displacement_gradient(u0, u1, u2, u3, dm_inv_of(rest[slot])));
}

// PHYSICS.md §1.2: V Psi(F), the corner forces V P b_a and the diagonal blocks
// V [mu |b|^2 I + max(c, 0) (cof F b)(cof F b)^T] (implicit/tet_tangent.rs).
@compute @workgroup_size(64)
fn evaluate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let slot = gid.x;
    var energy = 0.0;
    if (slot < NW.slot_count) {
        let o = slot * TET_STRIDE;
        if (live[slot] == 0u) {
            for (var a = 0u; a < 4u; a++) {
                tet_out[o + FORCE + a] = vec4<f32>(0.0);
                tet_out[o + DIAG + 2u * a] = vec4<f32>(0.0);
                tet_out[o + DIAG + 2u * a + 1u] = vec4<f32>(0.0);
            }
        } else {
            let r = rest[slot];
            let volume = r.c2.w;
            let s = strain_at(slot);
            let p = piola(s) * volume;
            let t = tangent_at(s);
            energy = volume * energy_density(s);
            let dm = dm_inv_of(r);
            let cplus = max(t.c, 0.0) * volume;
            for (var a = 0u; a < 4u; a++) {
                let b = shape_gradient(dm, a);
                tet_out[o + FORCE + a] = vec4<f32>(p * b, 0.0);
                let cb = t.cof * b;
                let m = NW.mu * dot(b, b) * volume;
                tet_out[o + DIAG + 2u * a] = vec4<f32>(m + cplus * cb.x * cb.x, m + cplus * cb.y * cb.y, m + cplus * cb.z * cb.z, cplus * cb.x * cb.y);
                tet_out[o + DIAG + 2u * a + 1u] = vec4<f32>(cplus * cb.x * cb.z, cplus * cb.y * cb.z, 0.0, 0.0);
            }
            tet_out[o + TANGENT] = vec4<f32>(t.f[0], t.c);
            tet_out[o + TANGENT + 1u] = vec4<f32>(t.f[1], t.s3);
            tet_out[o + TANGENT + 2u] = vec4<f32>(t.f[2], 0.0);
            tet_out[o + TANGENT + 3u] = vec4<f32>(t.cof[0], 0.0);
            tet_out[o + TANGENT + 4u] = vec4<f32>(t.cof[1], 0.0);
            tet_out[o + TANGENT + 5u] = vec4<f32>(t.cof[2], 0.0);
        }
    }
    let total = sum64(l, energy);
    if (l == 0u) {
        scratch[at_tet_energy() + wg.x] = total;
    }
}

// The elastic energy alone, computed and summed as `evaluate` does it.
@compute @workgroup_size(64)
fn energy(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let slot = gid.x;
    var e = 0.0;
    if (slot < NW.slot_count && live[slot] != 0u) {
        e = rest[slot].c2.w * energy_density(strain_at(slot));
    }
    let total = sum64(l, e);
    if (l == 0u) {
        scratch[at_tet_energy() + wg.x] = total;
    }
}

// A conjugate-gradient iteration's start and its product, per tet. Every workgroup
// reduces r . z (the same sum) and decides as the CPU's loop head does: stop at the
// product budget, at r . z <= 0 or below tol^2 of the first; else beta = r.z / the last
// r.z (workgroup 0 stores the decision for the later kernels). Then, with
// p = z + beta p_old at its corners (the update `gather_product` stores), the corner
// forces V dP[dF(p)] b_a.
@compute @workgroup_size(64)
fn product(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) l: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let rz = sum_partials64(l, at_rz(), NW.node_groups);
    let st = at_state();
    if (scratch[st + S_STOP] != 0.0 || scratch[st + S_NEG] != 0.0) {
        return;
    }
    let it = scratch[st + S_PRODUCTS];
    var first = scratch[st + S_FIRST];
    if (it == 0.0) {
        first = max(rz, TINY);
    }
    let lead = wg.x == 0u && l == 0u;
    if (it >= f32(NW.max_products) || !(rz > 0.0) || rz <= NW.tol2 * first) {
        if (lead) {
            scratch[st + S_STOP] = 1.0;
        }
        return;
    }
    let beta = select(rz / scratch[st + S_RZ], 0.0, it == 0.0);
    if (lead) {
        scratch[st + S_BETA] = beta;
        scratch[st + S_RZ_NEXT] = rz;
        scratch[st + S_FIRST] = first;
    }
    let slot = gid.x;
    if (slot >= NW.slot_count) {
        return;
    }
    let o = slot * TET_STRIDE;
    if (live[slot] == 0u) {
        for (var a = 0u; a < 4u; a++) {
            tet_out[o + PRODUCT + a] = vec4<f32>(0.0);
        }
        return;
    }
    let idx = tets[slot];
    let r = rest[slot];
    let d0 = vecs[vi(V_Z, idx.x)].xyz + beta * vecs[vi(V_P, idx.x)].xyz;
    let d1 = vecs[vi(V_Z, idx.y)].xyz + beta * vecs[vi(V_P, idx.y)].xyz;
    let d2 = vecs[vi(V_Z, idx.z)].xyz + beta * vecs[vi(V_P, idx.z)].xyz;
    let d3 = vecs[vi(V_Z, idx.w)].xyz + beta * vecs[vi(V_P, idx.w)].xyz;
    let dm = dm_inv_of(r);
    let df = displacement_gradient(d0, d1, d2, d3, dm);
    let f0 = tet_out[o + TANGENT];
    let f1 = tet_out[o + TANGENT + 1u];
    let f2 = tet_out[o + TANGENT + 2u];
    let t = Tangent(
        mat3x3<f32>(f0.xyz, f1.xyz, f2.xyz),
        mat3x3<f32>(tet_out[o + TANGENT + 3u].xyz, tet_out[o + TANGENT + 4u].xyz, tet_out[o + TANGENT + 5u].xyz),
        f0.w,
        f1.w,
    );
    let stress = tangent_dp(t, df) * r.c2.w;
    for (var a = 0u; a < 4u; a++) {
        tet_out[o + PRODUCT + a] = vec4<f32>(stress * shape_gradient(dm, a), 0.0);
    }
}
