// Neo-Hookean constraint projection of one colour, or of one phase of the partitioned
// order (PHYSICS.md §1.2, Macklin & Müller 2021):
// the rest-free pair C_H = ln J, C_D = sqrt(I_C - 3 - 2 ln J) (P.pair 0, default) or the
// seed's C_D = ||F||_F, C_H = det F - gamma (P.pair 1); coupled 2x2 solve (default) or H
// then D. Tets of one colour share no node, so each invocation owns its four nodes.
// CPU twins: crates/sim/src/xpbd/rest_free.rs and neo_hookean.rs (same operations in the
// same order).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> tets: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read> rest: array<TetRest>;
@group(0) @binding(4) var<storage, read> live: array<u32>;
@group(0) @binding(5) var<storage, read_write> lambda_h: array<f32>;
@group(1) @binding(0) var<uniform> S: Step;
// The partitioned order (`project_groups`, crates/sim/src/xpbd/sweep_plan.rs): runs[g *
// colours + c] = the slots (start, end) of group g and colour c; the groups of each phase.
@group(0) @binding(6) var<storage, read> runs: array<vec2<u32>>;
@group(0) @binding(7) var<storage, read> phase_groups: array<u32>;

// PHYSICS.md §1.2, table row C_H: d det F / dF = [f2 x f3, f3 x f1, f1 x f2].
fn det_gradient(f: mat3x3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(cross(f[1], f[2]), cross(f[2], f[0]), cross(f[0], f[1]));
}

var<private> g_a: array<vec3<f32>, 4>;
var<private> g_b: array<vec3<f32>, 4>;
var<private> x: array<vec3<f32>, 4>;
var<private> w: array<f32, 4>;

// Vertex gradients G = (dC/dF) Dm^-T: columns are grad x1..x3, grad x0 = -(sum).
fn gradients_a(dcdf: mat3x3<f32>, dm_inv: mat3x3<f32>) {
    let g = dcdf * transpose(dm_inv);
    g_a[0] = -(g[0] + g[1] + g[2]);
    g_a[1] = g[0];
    g_a[2] = g[1];
    g_a[3] = g[2];
}

fn gradients_b(dcdf: mat3x3<f32>, dm_inv: mat3x3<f32>) {
    let g = dcdf * transpose(dm_inv);
    g_b[0] = -(g[0] + g[1] + g[2]);
    g_b[1] = g[0];
    g_b[2] = g[1];
    g_b[3] = g[2];
}

fn dot_aa() -> f32 {
    return w[0] * dot(g_a[0], g_a[0]) + w[1] * dot(g_a[1], g_a[1]) + w[2] * dot(g_a[2], g_a[2]) + w[3] * dot(g_a[3], g_a[3]);
}

fn dot_ab() -> f32 {
    return w[0] * dot(g_a[0], g_b[0]) + w[1] * dot(g_a[1], g_b[1]) + w[2] * dot(g_a[2], g_b[2]) + w[3] * dot(g_a[3], g_b[3]);
}

fn dot_bb() -> f32 {
    return w[0] * dot(g_b[0], g_b[0]) + w[1] * dot(g_b[1], g_b[1]) + w[2] * dot(g_b[2], g_b[2]) + w[3] * dot(g_b[3], g_b[3]);
}

fn frobenius(f: mat3x3<f32>) -> f32 {
    return sqrt(dot(f[0], f[0]) + dot(f[1], f[1]) + dot(f[2], f[2]));
}

// One scalar XPBD update along g_a: dl = -C / (sum w |grad|^2 + alpha~).
fn apply_scalar_a(c: f32, alpha: f32) -> f32 {
    let denom = dot_aa() + alpha;
    if (!(denom > 0.0)) {
        return 0.0;
    }
    let dl = -c / denom;
    for (var i = 0; i < 4; i++) {
        x[i] += w[i] * g_a[i] * dl;
    }
    return dl;
}

fn project_coupled(dm_inv: mat3x3<f32>, alpha_h: f32, alpha_d: f32) -> f32 {
    let f = deformation_gradient(x[0], x[1], x[2], x[3], dm_inv);
    let c_h = determinant(f) - P.gamma;
    gradients_a(det_gradient(f), dm_inv);
    let norm = frobenius(f);
    if (norm < 1e-12) {
        return apply_scalar_a(c_h, alpha_h);
    }
    let c_d = norm;
    gradients_b(f * (1.0 / norm), dm_inv);
    var a = dot_aa() + alpha_h;
    var b = dot_ab();
    var d = dot_bb() + alpha_d;
    let s = 1.0 / (a + d);
    a *= s;
    b *= s;
    d *= s;
    let det = a * d - b * b;
    if (!(det > 0.0)) {
        return 0.0;
    }
    let r1 = -c_h * s;
    let r2 = -c_d * s;
    let dl_h = (r1 * d - b * r2) / det;
    let dl_d = (a * r2 - b * r1) / det;
    for (var i = 0; i < 4; i++) {
        x[i] += w[i] * (g_a[i] * dl_h + g_b[i] * dl_d);
    }
    return dl_h;
}

fn project_sequential(dm_inv: mat3x3<f32>, alpha_h: f32, alpha_d: f32) -> f32 {
    var f = deformation_gradient(x[0], x[1], x[2], x[3], dm_inv);
    gradients_a(det_gradient(f), dm_inv);
    let dl_h = apply_scalar_a(determinant(f) - P.gamma, alpha_h);
    f = deformation_gradient(x[0], x[1], x[2], x[3], dm_inv);
    let norm = frobenius(f);
    if (norm >= 1e-12) {
        gradients_a(f * (1.0 / norm), dm_inv);
        apply_scalar_a(norm, alpha_d);
    }
    return dl_h;
}

// A constraint value and its gradient dC/dF; c < 0 marks "no direction" (C_D at rest).
struct Term {
    c: f32,
    g: mat3x3<f32>,
}

// Rest-free C_H = L(J), dC_H/dF = L'(J) cof F.
fn rf_volume(s: Strain) -> Term {
    let l = log_volume(s);
    return Term(l.x, cof_f(s) * l.y);
}

// Rest-free C_D = sqrt(I_C - 3 - 2 L(J)), dC_D/dF = (F - L' cof F) / C_D.
fn rf_shape(s: Strain) -> Term {
    let j = 1.0 + s.j1;
    var psi: f32;
    var half: mat3x3<f32>;
    if (j > J_MIN) {
        psi = h_norm2(s) - 2.0 * s.i2 - 2.0 * s.det_h + 2.0 * log1p_excess(s.j1);
        half = j_f_minus_cof(s) * (1.0 / j);
    } else {
        let l = log_volume(s);
        psi = 2.0 * s.tr + h_norm2(s) - 2.0 * l.x;
        half = (IDENTITY3 + s.h) - cof_f(s) * l.y;
    }
    let c = sqrt(max(psi, 0.0));
    if (c < 1e-10) {
        return Term(-1.0, half);
    }
    return Term(c, half * (1.0 / c));
}

fn current_strain(dm_inv: mat3x3<f32>) -> Strain {
    return strain_of(displacement_gradient(x[0], x[1], x[2], x[3], dm_inv));
}

fn project_rest_free_coupled(dm_inv: mat3x3<f32>, alpha_h: f32, alpha_d: f32) -> f32 {
    let s = current_strain(dm_inv);
    let shape = rf_shape(s);
    let with_volume = alpha_h >= 0.0;
    let vol = rf_volume(s);
    gradients_a(vol.g, dm_inv);
    if (shape.c < 0.0) {
        if (with_volume) {
            return apply_scalar_a(vol.c, alpha_h);
        }
        return 0.0;
    }
    gradients_b(shape.g, dm_inv);
    if (!with_volume) {
        gradients_a(shape.g, dm_inv);
        apply_scalar_a(shape.c, alpha_d);
        return 0.0;
    }
    var a = dot_aa() + alpha_h;
    var b = dot_ab();
    var d = dot_bb() + alpha_d;
    let sc = 1.0 / (a + d);
    a *= sc;
    b *= sc;
    d *= sc;
    let det = a * d - b * b;
    if (!(det > 0.0)) {
        return 0.0;
    }
    let r1 = -vol.c * sc;
    let r2 = -shape.c * sc;
    let dl_h = (r1 * d - b * r2) / det;
    let dl_d = (a * r2 - b * r1) / det;
    for (var i = 0; i < 4; i++) {
        x[i] += w[i] * (g_a[i] * dl_h + g_b[i] * dl_d);
    }
    return dl_h;
}

fn project_rest_free_sequential(dm_inv: mat3x3<f32>, alpha_h: f32, alpha_d: f32) -> f32 {
    var dl_h = 0.0;
    if (alpha_h >= 0.0) {
        let vol = rf_volume(current_strain(dm_inv));
        gradients_a(vol.g, dm_inv);
        dl_h = apply_scalar_a(vol.c, alpha_h);
    }
    let shape = rf_shape(current_strain(dm_inv));
    if (shape.c >= 0.0) {
        gradients_a(shape.g, dm_inv);
        apply_scalar_a(shape.c, alpha_d);
    }
    return dl_h;
}

// Project the tet in `slot`, if it is live.
fn project_slot(slot: u32) {
    if (live[slot] == 0u) {
        return;
    }
    let idx = tets[slot];
    for (var i = 0; i < 4; i++) {
        let p = pos[idx[i]];
        x[i] = p.xyz;
        w[i] = p.w;
    }
    let r = rest[slot];
    let dm_inv = dm_inv_of(r);
    var dl_h: f32;
    if (P.pair == 0u && P.mode == 0u) {
        dl_h = project_rest_free_coupled(dm_inv, r.c0.w, r.c1.w);
    } else if (P.pair == 0u) {
        dl_h = project_rest_free_sequential(dm_inv, r.c0.w, r.c1.w);
    } else if (P.mode == 0u) {
        dl_h = project_coupled(dm_inv, r.c0.w, r.c1.w);
    } else {
        dl_h = project_sequential(dm_inv, r.c0.w, r.c1.w);
    }
    lambda_h[slot] = dl_h;
    for (var i = 0; i < 4; i++) {
        pos[idx[i]] = vec4<f32>(x[i], w[i]);
    }
}

// One colour over the whole mesh: S.first, S.count = its slots.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= S.count) {
        return;
    }
    project_slot(S.first + gid.x);
}

// One phase of the partitioned order (CPU twin: Solver::project_blocks): one workgroup
// per group (phase_groups[S.first + workgroup]), its tets colour after colour (S.count
// colours), the workgroup's invocations splitting each colour's run and meeting at a
// barrier before the next. The groups of a phase share no node, so a sweep needs one
// dispatch per phase instead of one per colour.
@compute @workgroup_size(64)
fn project_groups(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let g = phase_groups[S.first + wid.x];
    for (var c = 0u; c < S.count; c++) {
        let run = runs[g * S.count + c];
        for (var slot = run.x + li; slot < run.y; slot += 64u) {
            project_slot(slot);
        }
        storageBarrier();
        workgroupBarrier();
    }
}
