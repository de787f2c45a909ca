// Per-tet stress: the Cauchy stress of the model's energy (P.measure 0, default;
// docs/physics-notes.md "True stress": dev sigma = (mu/J) dev(F F^T), so von Mises needs no
// pressure and no rotation), or the seed's eq. 3 (PHYSICS.md §1.3: rotation by Müller et
// al. 2016, warm-started, sigma_T = mu((R^T F + F^T R)/2 - I) + lambda_H/(h^2 V) I, whose
// hydrostatic part drops out of the deviator); von Mises sqrt(3/2)||dev sigma||_F; also
// det F for the inversion guard.
// CPU twin: crates/sim/src/stress/ and Solver::compute_stress.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> tets: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read> rest: array<TetRest>;
@group(0) @binding(4) var<storage, read> live: array<u32>;
@group(0) @binding(5) var<storage, read_write> von_mises: array<f32>;
@group(0) @binding(6) var<storage, read_write> det_f: array<f32>;
@group(0) @binding(7) var<storage, read_write> rotation: array<vec4<f32>>;

fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz),
        a.w * b.w - dot(a.xyz, b.xyz),
    );
}

fn quat_to_mat(q: vec4<f32>) -> mat3x3<f32> {
    let x2 = q.x + q.x;
    let y2 = q.y + q.y;
    let z2 = q.z + q.z;
    let xx = q.x * x2;
    let xy = q.x * y2;
    let xz = q.x * z2;
    let yy = q.y * y2;
    let yz = q.y * z2;
    let zz = q.z * z2;
    let wx = q.w * x2;
    let wy = q.w * y2;
    let wz = q.w * z2;
    return mat3x3<f32>(
        vec3<f32>(1.0 - (yy + zz), xy + wz, xz - wy),
        vec3<f32>(xy - wz, 1.0 - (xx + zz), yz + wx),
        vec3<f32>(xz + wy, yz - wx, 1.0 - (xx + yy)),
    );
}

// PHYSICS.md §1.3, Müller et al. 2016 Alg. 1.
fn extract_rotation(a: mat3x3<f32>, q0: vec4<f32>) -> vec4<f32> {
    var q = q0;
    for (var it = 0; it < 20; it++) {
        let r = quat_to_mat(q);
        let num = cross(r[0], a[0]) + cross(r[1], a[1]) + cross(r[2], a[2]);
        let den = abs(dot(r[0], a[0]) + dot(r[1], a[1]) + dot(r[2], a[2])) + 1.0e-9;
        let omega = num * (1.0 / den);
        let angle = length(omega);
        if (angle < 1.0e-9) {
            break;
        }
        let axis = omega / angle;
        let half = 0.5 * angle;
        q = normalize(quat_mul(vec4<f32>(axis * sin(half), cos(half)), q));
    }
    return q;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let slot = gid.x;
    if (slot >= P.slot_count) {
        return;
    }
    if (live[slot] == 0u) {
        von_mises[slot] = 0.0;
        return;
    }
    let idx = tets[slot];
    let r = rest[slot];
    if (P.measure == 0u) {
        let s = strain_of(displacement_gradient(pos[idx[0]].xyz, pos[idx[1]].xyz, pos[idx[2]].xyz, pos[idx[3]].xyz, dm_inv_of(r)));
        let j = 1.0 + s.j1;
        // The pressure is isotropic: it leaves the deviator, so von Mises is that of
        // (mu/J)(F F^T - I) (CPU twin: cauchy_stress + von_mises).
        let shape = b_minus_i(s) * (P.mu / max(j, J_MIN));
        let mean = (shape[0].x + shape[1].y + shape[2].z) / 3.0;
        let dev = shape - IDENTITY3 * mean;
        von_mises[slot] = sqrt(1.5 * (dot(dev[0], dev[0]) + dot(dev[1], dev[1]) + dot(dev[2], dev[2])));
        det_f[slot] = j;
        return;
    }
    let f = deformation_gradient(pos[idx[0]].xyz, pos[idx[1]].xyz, pos[idx[2]].xyz, pos[idx[3]].xyz, dm_inv_of(r));
    let q = extract_rotation(f, rotation[slot]);
    let rm = quat_to_mat(q);
    let rtf = transpose(rm) * f;
    let sym = (rtf + transpose(rtf)) * 0.5;
    let eye = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    // dev sigma_T = mu dev S: the isotropic hydrostatic part cancels (CPU twin: tet_stress).
    let tr_s = sym[0].x + sym[1].y + sym[2].z;
    let dev = (sym - eye * (tr_s / 3.0)) * P.mu;
    let norm2 = dot(dev[0], dev[0]) + dot(dev[1], dev[1]) + dot(dev[2], dev[2]);
    von_mises[slot] = sqrt(1.5 * norm2);
    det_f[slot] = determinant(f);
    rotation[slot] = q;
}
