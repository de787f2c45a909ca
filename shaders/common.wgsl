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
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// One dispatch's range: a colour's slots, or the substep index for prediction.
struct Step {
    first: u32,
    count: u32,
    substep: u32,
    _pad: u32,
}

// Rest data of one tet slot: columns of Dm^-1 in xyz; c0.w = alpha~_H, c1.w = alpha~_D,
// c2.w = rest volume.
struct TetRest {
    c0: vec4<f32>,
    c1: vec4<f32>,
    c2: vec4<f32>,
}

const KIND_FREE: u32 = 0u;
const KIND_PINNED: u32 = 1u;
const KIND_RETIRED: u32 = 2u;
const KIND_GRAB0: u32 = 3u;

fn dm_inv_of(r: TetRest) -> mat3x3<f32> {
    return mat3x3<f32>(r.c0.xyz, r.c1.xyz, r.c2.xyz);
}

const IDENTITY3: mat3x3<f32> = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));

// PHYSICS.md §1.2: F = Ds Dm^-1 = I + Du Dm^-1, from node displacements u = x - X (the
// kernels' state; see Solver::u). CPU twin: deformation_gradient_from_displacement.
fn deformation_gradient(u0: vec3<f32>, u1: vec3<f32>, u2: vec3<f32>, u3: vec3<f32>, dm_inv: mat3x3<f32>) -> mat3x3<f32> {
    return IDENTITY3 + mat3x3<f32>(u1 - u0, u2 - u0, u3 - u0) * dm_inv;
}
