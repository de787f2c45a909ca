// Tool contact (PHYSICS.md §1.5): C = d(x) >= 0 for every free node, projected after the
// tet constraints of the substep, continuous over the substep (the node's path relative
// to each primitive), with positional Coulomb friction. One thread per node. Under the
// implicit scheme also before and between a step's solves, the nodes moved held
// (docs/physics-notes.md, "The implicit scheme under a blade").
// CPU twin: crates/sim/src/contact/projection.rs (project_node) and
// Solver::{project_contacts, hold_contacts, contacts}.
//
// tool: for each pose k = 0..=substeps (the tool at the end of substep k-1), a block of
// 2 vec4 (lower and upper corner of the bounds of all primitives), sphere_count vec4
// (xyz centre, w = +radius for cutting spheres, -radius otherwise), then box_count boxes
// of 4 vec4 (centre; axes 0..2 in xyz with the half extent in w).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> prev: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> kind: array<u32>;
@group(0) @binding(4) var<storage, read> rest_pos: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> tool: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> push: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> near_edge: array<u32>;
// Nodes the tool held through the last implicit step's solve (CPU twin: Solver::touched).
@group(0) @binding(8) var<storage, read_write> touch: array<u32>;
// Nodes `resolve` held (one counter).
@group(0) @binding(9) var<storage, read_write> moved: array<atomic<u32>>;
@group(1) @binding(0) var<uniform> S: Step;

// CPU twin: ON_SURFACE (m).
const ON_SURFACE: f32 = 1e-6;

// First sphere of pose k.
fn pose_base(k: u32) -> u32 {
    return k * (2u + P.sphere_count + 4u * P.box_count) + 2u;
}

struct Box {
    c: vec3<f32>,
    a0: vec3<f32>,
    a1: vec3<f32>,
    a2: vec3<f32>,
    h: vec3<f32>,
}

fn box_at(k: u32, b: u32) -> Box {
    let o = pose_base(k) + P.sphere_count + 4u * b;
    let a0 = tool[o + 1u];
    let a1 = tool[o + 2u];
    let a2 = tool[o + 3u];
    return Box(tool[o].xyz, a0.xyz, a1.xyz, a2.xyz, vec3<f32>(a0.w, a1.w, a2.w));
}

fn to_local(b: Box, x: vec3<f32>) -> vec3<f32> {
    let d = x - b.c;
    return vec3<f32>(dot(b.a0, d), dot(b.a1, d), dot(b.a2, d));
}

fn to_world(b: Box, l: vec3<f32>) -> vec3<f32> {
    return b.c + b.a0 * l.x + b.a1 * l.y + b.a2 * l.z;
}

// CPU twin: box_distance.
fn box_distance(l: vec3<f32>, h: vec3<f32>) -> f32 {
    let q = abs(l) - h;
    return length(max(q, vec3<f32>(0.0))) + min(max(q.x, max(q.y, q.z)), 0.0);
}

// CPU twin: push_out_of_sphere.
fn push_out_of_sphere(x_prev: vec3<f32>, x: vec3<f32>, c0: vec3<f32>, c1: vec3<f32>, r: f32, cutting: bool) -> vec3<f32> {
    let a = x_prev - c0;
    let b = x - c1;
    var n: vec3<f32>;
    if (length(a) > r + ON_SURFACE) {
        let e = b - a;
        let ee = dot(e, e);
        let ae = dot(a, e);
        let disc = ae * ae - ee * (dot(a, a) - r * r);
        if (ee <= 0.0 || disc < 0.0) {
            return x;
        }
        let t = (-ae - sqrt(disc)) / ee;
        if (t < 0.0 || t > 1.0) {
            return x;
        }
        let p = a + e * t;
        let lp = length(p);
        n = select(vec3<f32>(0.0, 0.0, 1.0), p / lp, lp > 0.0);
    } else if (dot(b, b) < r * r) {
        let la = length(a);
        let lb = length(b);
        let start = select(vec3<f32>(0.0, 0.0, 1.0), a / la, la > 0.0);
        n = start;
        if (!cutting && lb > 0.0 && dot(b / lb, start) > 0.0) {
            n = b / lb;
        }
    } else {
        return x;
    }
    return c1 + n * r;
}

// CPU twin: nearest_face. Returns (axis, side) as vec2: x = axis, y = +-1.
fn nearest_face(l: vec3<f32>, h: vec3<f32>) -> vec2<f32> {
    let q = abs(l) - h;
    var axis = 2u;
    if (q.x >= q.y && q.x >= q.z) {
        axis = 0u;
    } else if (q.y >= q.z) {
        axis = 1u;
    }
    return vec2<f32>(f32(axis), select(-1.0, 1.0, l[axis] >= 0.0));
}

// CPU twin: push_out_of_box.
fn push_out_of_box(x_prev: vec3<f32>, x: vec3<f32>, b0: Box, b1: Box) -> vec3<f32> {
    let h = b1.h;
    let l0 = to_local(b0, x_prev);
    var l1 = to_local(b1, x);
    if (box_distance(l0, h) > ON_SURFACE) {
        let e = l1 - l0;
        var t_in = -3.4e38;
        var t_out = 3.4e38;
        var axis = 0u;
        for (var i = 0u; i < 3u; i = i + 1u) {
            if (abs(e[i]) < 1e-12) {
                if (abs(l0[i]) > h[i]) {
                    return x;
                }
                continue;
            }
            var t1 = (-h[i] - l0[i]) / e[i];
            var t2 = (h[i] - l0[i]) / e[i];
            if (t1 > t2) {
                let tmp = t1;
                t1 = t2;
                t2 = tmp;
            }
            if (t1 > t_in) {
                t_in = t1;
                axis = i;
            }
            t_out = min(t_out, t2);
        }
        if (t_in > t_out || t_in < 0.0 || t_in > 1.0) {
            return x;
        }
        l1[axis] = select(h[axis], -h[axis], e[axis] > 0.0);
    } else {
        let f = nearest_face(l0, h);
        let axis = u32(f.x);
        if (l1[axis] * f.y >= h[axis]) {
            return x;
        }
        l1[axis] = f.y * h[axis];
    }
    return to_world(b1, l1);
}

// CPU twin: rigid_motion_at.
fn rigid_motion_at(x: vec3<f32>, k0: u32, k1: u32) -> vec3<f32> {
    if (P.box_count > 0u) {
        let b0 = box_at(k0, 0u);
        let b1 = box_at(k1, 0u);
        return x - to_world(b0, to_local(b1, x));
    }
    let f0 = pose_base(k0);
    let f1 = pose_base(k1);
    let last = P.sphere_count - 1u;
    let a0 = tool[f0].xyz;
    let a1 = tool[f1].xyz;
    let z0 = tool[f0 + last].xyz;
    let z1 = tool[f1 + last].xyz;
    let axis = z1 - a1;
    let len2 = dot(axis, axis);
    if (last > 0u && len2 > 0.0) {
        let t = clamp(dot(x - a1, axis) / len2, 0.0, 1.0);
        return mix(a1 - a0, z1 - z0, t);
    }
    return a1 - a0;
}

// Node i (free) projected out of the tool's path from its position at the step's start
// (`prev`) to `pos` (unchanged where the tool misses it), with friction; marks the node
// near the edge when within the cut reach of a cutting sphere.
fn projected(i: u32) -> vec3<f32> {
    let k0 = S.substep;
    let k1 = S.substep + 1u;
    let rest = rest_pos[i].xyz;
    let x_prev = rest + prev[i].xyz;
    let x_in = rest + pos[i].xyz;
    // Broad phase: the node's path against the tool's bounds (pose k0 and k1).
    let margin = max(P.reach, 0.0);
    let lo = min(tool[pose_base(k0) - 2u].xyz, tool[pose_base(k1) - 2u].xyz) - vec3<f32>(margin);
    let hi = max(tool[pose_base(k0) - 1u].xyz, tool[pose_base(k1) - 1u].xyz) + vec3<f32>(margin);
    if (any(max(x_prev, x_in) < lo) || any(min(x_prev, x_in) > hi)) {
        return x_in;
    }
    var p = x_in;
    let f0 = pose_base(k0);
    let f1 = pose_base(k1);
    for (var k = 0u; k < P.sphere_count; k = k + 1u) {
        let s0 = tool[f0 + k];
        let s1 = tool[f1 + k];
        p = push_out_of_sphere(x_prev, p, s0.xyz, s1.xyz, abs(s1.w), s1.w > 0.0);
    }
    for (var b = 0u; b < P.box_count; b = b + 1u) {
        p = push_out_of_box(x_prev, p, box_at(k0, b), box_at(k1, b));
    }
    let correction = p - x_in;
    let depth = length(correction);
    if (depth > 0.0 && P.friction > 0.0) {
        let normal = correction / depth;
        let rel = (p - x_prev) - rigid_motion_at(p, k0, k1);
        let tangential = rel - normal * dot(rel, normal);
        let slip = length(tangential);
        let limit = P.friction * depth;
        if (slip > 0.0) {
            if (slip <= limit) {
                p = p - tangential;
            } else {
                p = p - tangential * (limit / slip);
            }
        }
    }
    if (P.reach >= 0.0) {
        var d = 3.4e38;
        for (var k = 0u; k < P.sphere_count; k = k + 1u) {
            let s1 = tool[f1 + k];
            if (s1.w > 0.0) {
                d = min(d, length(p - s1.xyz) - s1.w);
            }
        }
        if (d < P.reach) {
            near_edge[i] = 3u; // this frame and this release window (release.wgsl)
        }
    }
    return p;
}

// The contact after a substep's tet constraints (or after an implicit step's solve): a
// node the solve held comes back free (touched: the next step starts it on the blade),
// every free node is projected, and one it moved books its m Δx.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= P.node_count) {
        return;
    }
    if (kind[i] == KIND_HELD) {
        kind[i] = KIND_FREE;
        touch[i] = 1u;
    }
    if (kind[i] != KIND_FREE) {
        return;
    }
    let cur = pos[i];
    let x_in = rest_pos[i].xyz + cur.xyz;
    let p = projected(i);
    if (any(p != x_in)) {
        pos[i] = vec4<f32>(p - rest_pos[i].xyz, cur.w);
        // m Δx with m = 1 / w (free nodes have w > 0).
        // (w: the implicit scheme's mark of a node its solve held, kept.)
        push[i] = vec4<f32>(push[i].xyz + (p - x_in) / cur.w, push[i].w);
    }
}

// The blade before an implicit step's solve (CPU twin: Solver::hold_contacts): a node it
// held in the last step starts where it was, every free node is projected, and one it
// moved is held through the solve.
@compute @workgroup_size(64)
fn hold(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= P.node_count) {
        return;
    }
    let was = touch[i];
    touch[i] = 0u;
    if (kind[i] != KIND_FREE) {
        return;
    }
    if (was != 0u) {
        pos[i] = vec4<f32>(prev[i].xyz, pos[i].w);
    }
    let x_in = rest_pos[i].xyz + pos[i].xyz;
    let p = projected(i);
    if (any(p != x_in)) {
        pos[i] = vec4<f32>(p - rest_pos[i].xyz, pos[i].w);
        kind[i] = KIND_HELD;
    }
}

// After an implicit step's solve: the free nodes it carried into the tool are projected
// out and held too; `moved[0]` counts them (the host solves again if any).
@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= P.node_count || kind[i] != KIND_FREE) {
        return;
    }
    let x_in = rest_pos[i].xyz + pos[i].xyz;
    let p = projected(i);
    if (any(p != x_in)) {
        pos[i] = vec4<f32>(p - rest_pos[i].xyz, pos[i].w);
        kind[i] = KIND_HELD;
        atomicAdd(&moved[0], 1u);
    }
}
