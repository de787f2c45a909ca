// Shared structs and helpers of the XPBD compute kernels (PHYSICS.md §1). Every stage file
// is compiled as common.wgsl + stage.wgsl; the Rust mirror of these structs is
// crates/sim/src/gpu/layout.rs. Node buffers hold displacements from the rest positions.

struct Params {
    gravity: vec3<f32>,
    h: f32,            // substep length, s
    inv_h: f32,        // 1 / h, computed on the host as the CPU solver does
    keep: f32,         // velocity damping factor max(0, 1 - damping h)
    gamma: f32,        // 1 + mu / lambda
    mu: f32,           // shear modulus, Pa
    threshold: f32,    // von Mises release threshold, Pa (<= 0: no cutting)
    node_count: u32,
    slot_count: u32,   // tets, in colour order
    grab_count: u32,
    mode: u32,         // 0: coupled H+D projection, 1: sequential H then D
    sphere_count: u32, // tool spheres (0: no tool)
    box_count: u32,    // tool boxes
    friction: f32,     // tool friction coefficient
    reach: f32,        // cut zone: release only near the edge, m; < 0: anywhere
    lambda: f32,       // volume stiffness, Pa: lambda (rest-free) or lambda_H (gamma-shifted)
    pair: u32,         // 0: rest-free pair, 1: the seed's gamma-shifted pair
    measure: u32,      // 0: Cauchy stress of the model, 1: the seed's eq. 3
}

// One dispatch's range: a colour's slots, or the substep index for prediction.
struct Step {
    first: u32,
    count: u32,
    substep: u32,
    _pad: u32,
}

// Rest data of one tet slot: columns of Dm^-1 in xyz; c0.w = alpha~_H (< 0: no volume
// constraint, lambda = 0), c1.w = alpha~_D, c2.w = rest volume.
struct TetRest {
    c0: vec4<f32>,
    c1: vec4<f32>,
    c2: vec4<f32>,
}

const KIND_FREE: u32 = 0u;
const KIND_PINNED: u32 = 1u;
const KIND_RETIRED: u32 = 2u;
const KIND_GRAB0: u32 = 3u;
// A free node the tool holds through an implicit step's solve (set and cleared within the
// step: contact.wgsl's hold/resolve and main).
const KIND_HELD: u32 = 0xffffffffu;

fn dm_inv_of(r: TetRest) -> mat3x3<f32> {
    return mat3x3<f32>(r.c0.xyz, r.c1.xyz, r.c2.xyz);
}

const IDENTITY3: mat3x3<f32> = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));

// PHYSICS.md §1.2: F = Ds Dm^-1 = I + Du Dm^-1, from node displacements u = x - X (the
// kernels' state; see Solver::u). CPU twin: deformation_gradient_from_displacement.
fn deformation_gradient(u0: vec3<f32>, u1: vec3<f32>, u2: vec3<f32>, u3: vec3<f32>, dm_inv: mat3x3<f32>) -> mat3x3<f32> {
    return IDENTITY3 + mat3x3<f32>(u1 - u0, u2 - u0, u3 - u0) * dm_inv;
}

// Invariants of F = I + H from the displacement gradient H, without cancellation
// (docs/physics-notes.md, rest-free Neo-Hookean). CPU twin: crates/sim/src/xpbd/strain.rs.
struct Strain {
    h: mat3x3<f32>,
    tr: f32,
    i2: f32,
    det_h: f32,
    j1: f32,      // J - 1 = tr H + I2(H) + det H
    cof_h: mat3x3<f32>,
}

// Below this J, ln J continues along its tangent (CPU twin: rest_free::J_MIN).
const J_MIN: f32 = 0.1;

fn cofactor(a: mat3x3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1]));
}

// PHYSICS.md §1.2: H = Du Dm^-1.
fn displacement_gradient(u0: vec3<f32>, u1: vec3<f32>, u2: vec3<f32>, u3: vec3<f32>, dm_inv: mat3x3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(u1 - u0, u2 - u0, u3 - u0) * dm_inv;
}

fn strain_of(h: mat3x3<f32>) -> Strain {
    let tr = h[0].x + h[1].y + h[2].z;
    let h2 = h * h;
    let tr_h2 = h2[0].x + h2[1].y + h2[2].z;
    let i2 = 0.5 * (tr * tr - tr_h2);
    let det_h = determinant(h);
    return Strain(h, tr, i2, det_h, tr + i2 + det_h, cofactor(h));
}

fn h_norm2(s: Strain) -> f32 {
    return dot(s.h[0], s.h[0]) + dot(s.h[1], s.h[1]) + dot(s.h[2], s.h[2]);
}

// cof F = (1 + tr H) I - H^T + cof H.
fn cof_f(s: Strain) -> mat3x3<f32> {
    return IDENTITY3 * (1.0 + s.tr) - transpose(s.h) + s.cof_h;
}

// J F - cof F = (I2 + det H) I + H + H^T + (J - 1) H - cof H.
fn j_f_minus_cof(s: Strain) -> mat3x3<f32> {
    return IDENTITY3 * (s.i2 + s.det_h) + s.h + transpose(s.h) + s.h * s.j1 - s.cof_h;
}

// F F^T - I = H + H^T + H H^T.
fn b_minus_i(s: Strain) -> mat3x3<f32> {
    return s.h + transpose(s.h) + s.h * transpose(s.h);
}

// x - ln(1 + x), series below |x| = 0.1 (CPU twin: strain::log1p_excess).
fn log1p_excess(x: f32) -> f32 {
    if (abs(x) < 0.1) {
        let x2 = x * x;
        var tail = -1.0 / 7.0 + x * 0.125;
        tail = -0.2 + x * (1.0 / 6.0 + x * tail);
        return x2 * (0.5 + x * (-1.0 / 3.0 + x * (0.25 + x * tail)));
    }
    return x - log(1.0 + x);
}

// (L(J), L'(J)): ln J and 1/J, continued linearly below J_MIN (CPU twin: log_volume).
fn log_volume(s: Strain) -> vec2<f32> {
    let j = 1.0 + s.j1;
    if (j > J_MIN) {
        return vec2<f32>(s.j1 - log1p_excess(s.j1), 1.0 / j);
    }
    return vec2<f32>(log(J_MIN) + (j - J_MIN) / J_MIN, 1.0 / J_MIN);
}
