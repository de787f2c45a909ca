// Release by the von Mises criterion (PHYSICS.md §1.4, seed eq. 5), run at each release
// check of the frame: a live tet whose stress exceeds the threshold loses its constraints
// (a flag; nothing is deleted) and is appended to the list of tets released this frame,
// which the host reads back to update the cut surface. near_edge holds two bits per node:
// 1 = came near a cutting sphere this frame, 2 = since the last check (what the cut zone
// releases by; `clear_window` clears it after the check).
// CPU twin: Solver::switch_off_overstressed.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> von_mises: array<f32>;
@group(0) @binding(2) var<storage, read_write> live: array<u32>;
@group(0) @binding(3) var<storage, read_write> released_count: atomic<u32>;
@group(0) @binding(4) var<storage, read_write> released_list: array<u32>;
@group(0) @binding(5) var<storage, read> tets: array<vec4<u32>>;
@group(0) @binding(6) var<storage, read_write> near_edge: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let slot = gid.x;
    if (slot >= P.slot_count || P.threshold <= 0.0) {
        return;
    }
    // Cut zone (CutZone::NearEdge): only tets with a node the cutting edge came near.
    if (P.reach >= 0.0) {
        let t = tets[slot];
        if (((near_edge[t.x] | near_edge[t.y] | near_edge[t.z] | near_edge[t.w]) & 2u) == 0u) {
            return;
        }
    }
    if (live[slot] != 0u && von_mises[slot] > P.threshold) {
        live[slot] = 0u;
        let k = atomicAdd(&released_count, 1u);
        released_list[k] = slot;
    }
}

// After a check: the cut-zone window starts again (bit 2), the frame's bit stays.
@compute @workgroup_size(64)
fn clear_window(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x < P.node_count) {
        near_edge[gid.x] = near_edge[gid.x] & 1u;
    }
}

// At the start of a frame: the frame's bit clears, the window's bit stays.
@compute @workgroup_size(64)
fn clear_frame(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x < P.node_count) {
        near_edge[gid.x] = near_edge[gid.x] & 2u;
    }
}
