//! Shared set-up for the physics validation tests.
#![allow(dead_code)]

pub mod linear_fem;
pub mod stretched_bar;

use glam::{UVec3, Vec3};
use incise_sim::generate::block;
use incise_sim::xpbd::{TetOrder, stiffness_number, substeps_needed};
use incise_sim::{Material, Solver, SolverParams, TetMesh};

/// A validated block mesh from `min` with edge lengths `size`, `cells` hexes.
pub fn block_mesh(min: Vec3, size: Vec3, cells: UVec3) -> TetMesh {
    TetMesh::from_raw(block(min, size, cells))
        .expect("generated block is valid")
        .0
}

/// A soft tissue-like material.
pub fn soft(e: f32, nu: f32) -> Material {
    Material {
        youngs_modulus: e,
        poisson_ratio: nu,
        density: 1000.0,
    }
}

/// Solver with the given settings; the substep count is raised to the stability bound
/// (`incise_sim::xpbd::stiffness_number`) when the given one is too low.
pub fn solver(mesh: TetMesh, m: Material, mut params: SolverParams) -> Solver {
    params.substeps = stable_substeps(&mesh, &m, &params);
    Solver::new(mesh, m, params).expect("valid solver settings")
}

/// Solver whose substeps bring the worst tet's stiffness number down to `kappa` (XPBD's
/// one iteration per substep reaches the energy minimum only as κ → 0: at the bound κ = 1
/// static stresses are a few per cent off, docs/physics-notes.md).
pub fn solver_at_kappa(mesh: TetMesh, m: Material, mut params: SolverParams, kappa: f32) -> Solver {
    params.substeps = 1;
    let w: Vec<f32> = mesh
        .lumped_masses(m.density)
        .iter()
        .map(|&x| 1.0 / x)
        .collect();
    let (k1, _) = stiffness_number(&mesh, &w, m.lame(), params.substep());
    params.substeps = (k1 / kappa).sqrt().ceil().max(1.0) as u32;
    Solver::new(mesh, m, params).expect("valid solver settings")
}

/// The larger of `params.substeps` and the fewest substeps the stability bound allows.
pub fn stable_substeps(mesh: &TetMesh, m: &Material, params: &SolverParams) -> u32 {
    let w: Vec<f32> = mesh
        .lumped_masses(m.density)
        .iter()
        .map(|&x| 1.0 / x)
        .collect();
    let (kappa, _) = stiffness_number(mesh, &w, m.lame(), params.substep());
    params.substeps.max(substeps_needed(kappa, params.substeps))
}

/// Largest distance of any node from its rest position.
pub fn max_displacement(s: &Solver) -> f32 {
    s.positions()
        .iter()
        .zip(&s.mesh().rest_positions)
        .map(|(x, r)| (*x - *r).length())
        .fold(0.0, f32::max)
}

/// A wgpu device for GPU tests, or `None` (with the reason printed) when no adapter exists;
/// a failure instead where the GPU is required (`incise_test_gate`: `INCISE_REQUIRE_GPU=1`,
/// or `CI` set with it unset).
#[cfg(feature = "gpu")]
pub fn gpu_context() -> Option<incise_sim::gpu::GpuContext> {
    incise_test_gate::or_skip(
        incise_test_gate::Need::Gpu,
        incise_sim::gpu::GpuContext::new(),
    )
}

/// Edge length of the compression test cube, m.
pub const CUBE: f32 = 0.02;

/// A ν = 0.49 cube of [`CUBE`] edge (8 cells per side, E = 10 kPa, 200 substeps, damping
/// 20/s, no gravity): bottom face pinned, top face driven down by 20 % of the height at
/// 2 cm/s (no-slip plates). Returns the solver and the top nodes.
pub fn compressed_cube(
    hydrostatic: incise_sim::material::HydrostaticStiffness,
    threads: usize,
) -> (Solver, Vec<u32>) {
    use incise_sim::grab::Grab;
    use incise_sim::selection::NodeSelection;
    let mesh = block_mesh(Vec3::ZERO, Vec3::splat(CUBE), UVec3::new(8, 8, 8));
    let params = SolverParams {
        gravity: Vec3::ZERO,
        substeps: 200,
        damping: 20.0,
        threads,
        hydrostatic,
        ..SolverParams::default()
    };
    let mut s = solver(mesh, soft(10e3, 0.49), params);
    let rest = s.mesh().rest_positions.clone();
    let bottom = NodeSelection::PlaneSide {
        point: Vec3::new(0.0, 0.0, 1e-4),
        normal: -Vec3::Z,
    };
    let top = NodeSelection::PlaneSide {
        point: Vec3::new(0.0, 0.0, CUBE - 1e-4),
        normal: Vec3::Z,
    };
    s.pin(&bottom.select(&rest).expect("bottom face"));
    let top = top.select(&rest).expect("top face");
    s.add_grab(Grab {
        nodes: top.clone(),
        waypoints: vec![Vec3::new(0.0, 0.0, -0.2 * CUBE)],
        speed: 0.02,
        start_time: 0.0,
    });
    (s, top)
}

/// A 10 × 3 × 3 cm bar (E = 30 kPa, ν = 0.4, release at 6 kPa) pinned at x = 0 and pulled
/// from x = 10 cm along (5, 0, 1) cm at 10 cm/s until it tears.
pub fn tearing_bar(threads: usize) -> Solver {
    tearing_bar_with(|p| p.threads = threads)
}

/// [`tearing_bar`] with its settings (release at 6 kPa, the rest default) changed by
/// `adjust`.
pub fn tearing_bar_with(adjust: impl FnOnce(&mut SolverParams)) -> Solver {
    tearing_bar_on(tearing_bar_mesh(), TetOrder::default(), adjust)
}

/// The tearing bar's mesh: 20 × 6 × 6 hexes of 5 mm, six tets each.
pub fn tearing_bar_mesh() -> TetMesh {
    block_mesh(Vec3::ZERO, Vec3::new(0.1, 0.03, 0.03), UVec3::new(20, 6, 6))
}

/// [`tearing_bar_with`] on `mesh` (the bar's, its tets listed in any order), the solver's
/// tets stored in `order` inside each colour.
pub fn tearing_bar_on(
    mesh: TetMesh,
    order: TetOrder,
    adjust: impl FnOnce(&mut SolverParams),
) -> Solver {
    use incise_sim::grab::Grab;
    use incise_sim::selection::NodeSelection;
    let mut params = SolverParams {
        release_threshold: Some(6e3),
        ..SolverParams::default()
    };
    adjust(&mut params);
    let m = soft(30e3, 0.4);
    params.substeps = stable_substeps(&mesh, &m, &params);
    let mut s = Solver::with_tet_order(mesh, m, params, order).expect("valid solver settings");
    let rest = s.mesh().rest_positions.clone();
    let left = NodeSelection::PlaneSide {
        point: Vec3::new(0.002, 0.0, 0.0),
        normal: -Vec3::X,
    };
    s.pin(&left.select(&rest).expect("left end"));
    let right = NodeSelection::PlaneSide {
        point: Vec3::new(0.098, 0.0, 0.0),
        normal: Vec3::X,
    };
    s.add_grab(Grab {
        nodes: right.select(&rest).expect("right end"),
        waypoints: vec![Vec3::new(0.05, 0.0, 0.01)],
        speed: 0.1,
        start_time: 0.0,
    });
    s
}

/// A blade in the tool's x–z plane: `count` cutting spheres of radius `r`, `spacing`
/// apart along x from the origin (the edge is their lower envelope), and a 0.4 mm thick
/// non-cutting flat above them, friction 0.2.
pub fn blade(count: usize, r: f32, spacing: f32) -> incise_sim::contact::ContactTool {
    use incise_sim::contact::{ContactTool, ToolBox, ToolSphere};
    let length = spacing * (count - 1) as f32;
    ContactTool {
        spheres: (0..count)
            .map(|i| ToolSphere {
                centre: Vec3::new(i as f32 * spacing, 0.0, 0.0),
                radius: r,
                cutting: true,
            })
            .collect(),
        boxes: vec![ToolBox {
            centre: Vec3::new(length / 2.0, 0.0, r + 0.01),
            rotation: glam::Quat::IDENTITY,
            half_extents: Vec3::new(length / 2.0 + r, 0.0002, 0.01),
        }],
        friction: 0.2,
    }
}

/// Top of the pressed block ([`pressed_block`]), m.
pub const PRESSED_TOP: f32 = 0.012;
/// Radius of the pressing blade's spheres, m.
pub const PRESSED_BLADE_R: f32 = 0.003;

/// A soft block (4 × 2 × 1.2 cm, 10 kPa, ν = 0.45) with its bottom pinned and a
/// four-sphere [`blade`] placed at `blade_at`, on `params`: what a blade presses into.
pub fn pressed_block(params: SolverParams, blade_at: Vec3) -> Solver {
    let mesh = block_mesh(
        Vec3::ZERO,
        Vec3::new(0.04, 0.02, PRESSED_TOP),
        UVec3::new(8, 4, 3),
    );
    let mut s = Solver::new(mesh, soft(10e3, 0.45), params).unwrap();
    let bottom: Vec<u32> = (0..s.mesh().node_count() as u32)
        .filter(|&i| s.mesh().rest_positions[i as usize].z < 1e-4)
        .collect();
    s.pin(&bottom);
    let r = PRESSED_BLADE_R;
    s.set_tool(
        blade(4, r, r),
        incise_sim::contact::ToolPose::new(blade_at, glam::Quat::IDENTITY),
    )
    .unwrap();
    s
}

/// Top of the incision block, m.
pub const INCISION_TOP: f32 = 0.02;
/// Blade depth of the scripted incision below the top, m.
pub const INCISION_DEPTH: f32 = 0.006;

/// A 6 × 3 × 2 cm soft block (E = 10 kPa, ν = 0.45, no gravity, release at 3 kPa near the
/// edge), bottom pinned, and an 8-sphere blade (r = half the mean edge length) 2 mm
/// above its top. Returns the solver (tool attached), the sphere radius and the blade's
/// path: down to [`INCISION_DEPTH`], then 3 cm along x (the blade spans 1.1 cm ahead of
/// its origin, so its front stops 9 mm before the block's end).
pub fn incision_block(
    threads: usize,
    tool: Option<incise_sim::contact::ContactTool>,
) -> (Solver, f32, Vec<Vec3>) {
    use incise_sim::contact::{CutZone, ToolPose};
    use incise_sim::selection::NodeSelection;
    let mesh = block_mesh(
        Vec3::ZERO,
        Vec3::new(0.06, 0.03, INCISION_TOP),
        UVec3::new(24, 12, 8),
    );
    let edge = mesh.mean_edge_length();
    let params = SolverParams {
        gravity: Vec3::ZERO,
        damping: 10.0,
        threads,
        // 3 kPa of the seed's eq. 3 stress; the Cauchy stress is twice it at small strain.
        release_threshold: Some(6e3),
        cut_zone: CutZone::NearEdge { reach: 0.25 * edge },
        ..SolverParams::default()
    };
    let mut s = solver(mesh, soft(10e3, 0.45), params);
    let rest = s.mesh().rest_positions.clone();
    let bottom = NodeSelection::PlaneSide {
        point: Vec3::new(0.0, 0.0, 1e-4),
        normal: -Vec3::Z,
    };
    s.pin(&bottom.select(&rest).expect("bottom face"));
    let r = 0.5 * edge;
    let start = Vec3::new(0.01, 0.015, INCISION_TOP + r + 0.002);
    let down = start - Vec3::Z * (INCISION_DEPTH + 0.002);
    let end = down + Vec3::X * 0.03;
    let tool = tool.unwrap_or_else(|| blade(8, r, r));
    s.set_tool(tool, ToolPose::new(start, glam::Quat::IDENTITY))
        .expect("valid tool");
    (s, r, vec![start, down, end])
}

/// Frame-by-frame targets of a tool moving through `path` at `speed`, holding `hold`
/// frames at each waypoint.
pub fn tool_targets(path: &[Vec3], speed: f32, dt: f32, hold: usize) -> Vec<Vec3> {
    let mut out = Vec::new();
    for w in path.windows(2) {
        let frames = ((w[1] - w[0]).length() / (speed * dt)).ceil().max(1.0) as usize;
        for f in 1..=frames {
            out.push(w[0].lerp(w[1], f as f32 / frames as f32));
        }
        out.extend(std::iter::repeat_n(w[1], hold));
    }
    out
}

/// Largest distance between matching nodes of two position sets, m.
pub fn worst_gap(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (*p - *q).length())
        .fold(0.0, f32::max)
}
