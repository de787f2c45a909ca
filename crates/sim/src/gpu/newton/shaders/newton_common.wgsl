// Shared definitions of the implicit (Newton) scheme's kernels (docs/physics-notes.md,
// "The implicit scheme"; CPU reference: crates/sim/src/implicit/). Each Newton stage is
// compiled as common.wgsl + newton_common.wgsl + the stage; the Rust mirror of `Newton` and
// of the scratch layout is crates/sim/src/gpu/newton/layout.rs.

struct Newton {
    node_count: u32,
    slot_count: u32,
    coarse_nodes: u32,
    max_products: u32, // conjugate-gradient products per Newton iteration
    inv_h2: f32,       // 1 / h^2 of the implicit step
    mu: f32,
    lambda: f32,
    tol2: f32,         // cg_tolerance^2
    fall: vec3<f32>,   // h^2 g: what the first iterate leaves out of the prediction
    alpha: f32,        // the line search's step along the direction
    node_groups: u32,  // partial sums of a node reduction (one per 64 nodes)
    tet_groups: u32,   // partial sums of a tet reduction (one per 64 slots)
    transpose_at: u32, // where coarse_map's per-coarse-node offsets start
    _pad: u32,
}

// Node vectors: slice k of `vecs` holds node i at k * node_count + i.
const V_Y: u32 = 0u;      // the prediction y (w: inverse mass, as pos)
const V_TRIAL: u32 = 1u;  // the point evaluated (w: inverse mass)
const V_G: u32 = 2u;      // gradient of G at the last full evaluation
const V_X: u32 = 3u;      // the conjugate gradient's solution: the Newton direction
const V_R: u32 = 4u;      // its residual
const V_P: u32 = 5u;      // its search direction
const V_AP: u32 = 6u;     // Hessian times P
const V_Z: u32 = 7u;      // preconditioned residual
const V_DINV: u32 = 8u;   // three slices: columns of the inverted diagonal block
const V_MASS: u32 = 11u;  // x: lumped mass, kg
const V_SLICES: u32 = 12u;

// Per slot, TET_STRIDE vec4 of `tet_out`: forces of the four corners, their diagonal
// blocks (two vec4 each: xx yy zz xy, xz yz), the tangent (F's columns with c and s3 in w,
// then cof F's columns) and the Hessian product's four corner forces.
const TET_STRIDE: u32 = 22u;
const FORCE: u32 = 0u;
const DIAG: u32 = 4u;
const TANGENT: u32 = 12u;
const PRODUCT: u32 = 18u;

// Scratch: partial sums, then the conjugate gradient's state.
fn at_tet_energy() -> u32 { return 0u; }
fn at_inertia() -> u32 { return NW.tet_groups; }
fn at_grad2() -> u32 { return NW.tet_groups + NW.node_groups; }
fn at_rz() -> u32 { return NW.tet_groups + 2u * NW.node_groups; }
fn at_pap() -> u32 { return NW.tet_groups + 3u * NW.node_groups; }
fn at_slope() -> u32 { return NW.tet_groups + 4u * NW.node_groups; }
fn at_reach() -> u32 { return NW.tet_groups + 5u * NW.node_groups; }
fn at_state() -> u32 { return NW.tet_groups + 6u * NW.node_groups; }
const S_STOP: u32 = 0u;     // 1: the solve stopped (tolerance, product budget, rz <= 0)
const S_NEG: u32 = 1u;      // 1: it met non-positive curvature
const S_PRODUCTS: u32 = 2u; // products spent
const S_FIRST: u32 = 3u;    // r0.z0
const S_RZ: u32 = 4u;       // r.z of the current iteration
const S_BETA: u32 = 5u;
const S_ALPHA: u32 = 6u;
const S_RZ_NEXT: u32 = 7u; // r.z as `product` reduced it, until `gather_product` books it

// f64::MIN_POSITIVE's role in the CPU's first r.z (no division by zero).
const TINY: f32 = 1.17549435e-38;

var<workgroup> red: array<f32, 256>;

// Sum of v over a 64-thread workgroup (thread l); every thread gets it.
fn sum64(l: u32, v: f32) -> f32 {
    red[l] = v;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s = s >> 1u) {
        if (l < s) {
            red[l] = red[l] + red[l + s];
        }
        workgroupBarrier();
    }
    let total = red[0];
    workgroupBarrier();
    return total;
}

// Largest v over a 64-thread workgroup (thread l); every thread gets it.
fn max64(l: u32, v: f32) -> f32 {
    red[l] = v;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s = s >> 1u) {
        if (l < s) {
            red[l] = max(red[l], red[l + s]);
        }
        workgroupBarrier();
    }
    let top = red[0];
    workgroupBarrier();
    return top;
}

// The sum of `count` partial sums from `at`, by a 64-thread workgroup; every thread gets
// it (each workgroup of a dispatch sums them in the same order: the same value).
fn sum_partials64(l: u32, at: u32, count: u32) -> f32 {
    var v = 0.0;
    for (var k = l; k < count; k += 64u) {
        v += scratch[at + k];
    }
    return sum64(l, v);
}

// The 3 x 3 symmetric block stored as (xx yy zz xy), (xz yz).
fn sym_block(a: vec4<f32>, b: vec4<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(a.x, a.w, b.x), vec3<f32>(a.w, a.y, b.y), vec3<f32>(b.x, b.y, a.z));
}

// The shape gradients b_a = dF/dx_a of a tet (CPU twin: vbd::shape_gradients).
fn shape_gradient(dm_inv: mat3x3<f32>, a: u32) -> vec3<f32> {
    let t = transpose(dm_inv);
    if (a == 0u) {
        return -(t[0] + t[1] + t[2]);
    }
    return t[a - 1u];
}

// psi^ = I_C - 3 - 2 L(J) >= 0 and half its gradient F - L' cof F, from H
// (docs/physics-notes.md, rest-free pair; CPU twin: xpbd::shape_energy).
struct ShapeEnergy {
    psi: f32,
    half: mat3x3<f32>,
}

fn shape_energy(s: Strain) -> ShapeEnergy {
    let j = 1.0 + s.j1;
    if (j > J_MIN) {
        let psi = h_norm2(s) - 2.0 * s.i2 - 2.0 * s.det_h + 2.0 * log1p_excess(s.j1);
        return ShapeEnergy(max(psi, 0.0), j_f_minus_cof(s) * (1.0 / j));
    }
    let lv = log_volume(s);
    let f = IDENTITY3 + s.h;
    return ShapeEnergy(max(2.0 * s.tr + h_norm2(s) - 2.0 * lv.x, 0.0), f - cof_f(s) * lv.y);
}

// PHYSICS.md §1.2's energy density, mu/2 psi^ + lambda/2 L^2 (CPU twin: vbd::energy_density).
fn energy_density(s: Strain) -> f32 {
    let l = log_volume(s).x;
    return 0.5 * NW.mu * shape_energy(s).psi + 0.5 * NW.lambda * l * l;
}

// First Piola-Kirchhoff stress mu (F - L' cof F) + lambda L L' cof F (CPU twin: vbd::piola).
fn piola(s: Strain) -> mat3x3<f32> {
    let lv = log_volume(s);
    return shape_energy(s).half * NW.mu + cof_f(s) * (NW.lambda * lv.x * lv.y);
}

// The stress tangent (CPU twin: implicit::TetTangent): F, cof F, c and s3.
struct Tangent {
    f: mat3x3<f32>,
    cof: mat3x3<f32>,
    c: f32,
    s3: f32,
}

fn tangent_at(s: Strain) -> Tangent {
    let lv = log_volume(s);
    let j = 1.0 + s.j1;
    var ddl = 0.0;
    if (j > J_MIN) {
        ddl = -lv.y * lv.y;
    }
    let pressure = NW.lambda * lv.x - NW.mu;
    return Tangent(IDENTITY3 + s.h, cof_f(s), NW.lambda * lv.y * lv.y + pressure * ddl, pressure * lv.y);
}

fn frobenius_dot(a: mat3x3<f32>, b: mat3x3<f32>) -> f32 {
    return dot(a[0], b[0]) + dot(a[1], b[1]) + dot(a[2], b[2]);
}

// dP[dF] = mu dF + c (cof F : dF) cof F + s3 dcof[dF] (implicit/tet_tangent.rs).
fn tangent_dp(t: Tangent, df: mat3x3<f32>) -> mat3x3<f32> {
    let dj = frobenius_dot(t.cof, df);
    let f = t.f;
    let dcof = mat3x3<f32>(
        cross(df[1], f[2]) + cross(f[1], df[2]),
        cross(df[2], f[0]) + cross(f[2], df[0]),
        cross(df[0], f[1]) + cross(f[0], df[1]),
    );
    return df * NW.mu + t.cof * (t.c * dj) + dcof * t.s3;
}

// Index of node i in slice `slice` of `vecs`.
fn vi(slice: u32, i: u32) -> u32 {
    return slice * NW.node_count + i;
}
