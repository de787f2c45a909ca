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
