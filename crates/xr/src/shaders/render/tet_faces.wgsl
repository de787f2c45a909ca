// Faces of live tets drawn straight from the node positions (vertex pulling): the cut
// surface (faces bordering released tets) in the wet-tissue material, and, for the stress
// overlay, every visible face coloured by its tet's von Mises stress.

// One face: three node indices wound outward from its live tet, and that tet.
@group(0) @binding(1) var<storage, read> nodes: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> von_mises: array<f32>;
@group(0) @binding(3) var<storage, read> cut_faces: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read> surface_faces: array<vec4<u32>>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) normal: vec3<f32>,
    @location(2) @interpolate(flat) stress: f32,
};

fn face_vertex(face: vec4<u32>, corner: u32) -> VsOut {
    let a = nodes[face.x].xyz;
    let b = nodes[face.y].xyz;
    let c = nodes[face.z].xyz;
    var p = a;
    if (corner == 1u) { p = b; }
    if (corner == 2u) { p = c; }
    var out: VsOut;
    out.clip = g.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    let n = cross(b - a, c - a);
    out.normal = n / max(length(n), 1e-20);
    out.stress = von_mises[face.w];
    return out;
}

@vertex
fn vs_cut(@builtin(vertex_index) vi: u32) -> VsOut {
    return face_vertex(cut_faces[vi / 3u], vi % 3u);
}

@vertex
fn vs_surface(@builtin(vertex_index) vi: u32) -> VsOut {
    return face_vertex(surface_faces[vi / 3u], vi % 3u);
}

fn facing(n: vec3<f32>, front: bool) -> vec3<f32> {
    if (front) { return n; }
    return -n;
}

@fragment
fn fs_cut(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return finish(shade(cut_material(), facing(in.normal, front), in.world), ID_CUT);
}

// Turbo colour map (Mikhailov 2019, polynomial fit), t in [0, 1].
fn turbo(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0);
    let r4 = vec4<f32>(0.13572138, 4.61539260, -42.66032258, 132.13108234);
    let g4 = vec4<f32>(0.09140261, 2.19418839, 4.84296658, -14.18503333);
    let b4 = vec4<f32>(0.10667330, 12.64194608, -60.58204836, 110.36276771);
    let r2 = vec2<f32>(-152.94239396, 59.28637943);
    let g2 = vec2<f32>(4.27729857, 2.82956604);
    let b2 = vec2<f32>(-89.90310912, 27.34824973);
    let v4 = vec4<f32>(1.0, x, x * x, x * x * x);
    let v2 = v4.zw * v4.z;
    return vec3<f32>(dot(v4, r4) + dot(v2, r2), dot(v4, g4) + dot(v2, g2), dot(v4, b4) + dot(v2, b2));
}

@fragment
fn fs_stress(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let colour = turbo(in.stress * g.misc.x);
    // sRGB colour-map values to linear, lit softly so the shape still reads.
    let albedo = pow(clamp(colour, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(2.2));
    let m = Material(albedo, 0.6, 0.02, 0.6, vec3<f32>(1.0));
    return finish(shade(m, facing(in.normal, front), in.world) * 1.3, ID_STRESS);
}
