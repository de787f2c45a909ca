//! Shared set-up for the physics validation tests.
#![allow(dead_code)]

use glam::{UVec3, Vec3};
use incise_sim::generate::block;
use incise_sim::xpbd::{stiffness_number, substeps_needed};
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

/// A wgpu device for GPU tests, or `None` (with the reason printed) when no adapter exists.
/// With `INCISE_REQUIRE_GPU=1` (CI) a missing adapter fails the test instead.
#[cfg(feature = "gpu")]
pub fn gpu_context() -> Option<incise_sim::gpu::GpuContext> {
    match incise_sim::gpu::GpuContext::new() {
        Ok(c) => Some(c),
        Err(e) if std::env::var("INCISE_REQUIRE_GPU").is_ok_and(|v| v == "1") => {
            panic!("INCISE_REQUIRE_GPU=1 but {e}")
        }
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
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
    use incise_sim::grab::Grab;
    use incise_sim::selection::NodeSelection;
    let mesh = block_mesh(Vec3::ZERO, Vec3::new(0.1, 0.03, 0.03), UVec3::new(20, 6, 6));
    let params = SolverParams {
        threads,
        release_threshold: Some(6e3),
        ..SolverParams::default()
    };
    let mut s = solver(mesh, soft(30e3, 0.4), params);
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
