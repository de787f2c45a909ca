//! VBD: a body at rest with no load stays exactly at rest (every displacement is 0.0,
//! not merely small) for ν = 0, 0.3, 0.45, 0.499, with pins, Rayleigh damping,
//! Chebyshev acceleration and every initial guess: the rest-free energy has exactly zero
//! gradient at `H = 0`, so every local Newton step is exactly zero.

mod vbd_support;

use glam::UVec3;
use incise_sim::Material;
use incise_sim::vbd::{InitialGuess, VbdSolver};
use vbd_support::{bar_mesh, end_nodes, vbd_params};

#[test]
fn rest_stays_exactly_at_rest() {
    for nu in [0.0, 0.3, 0.45, 0.499] {
        for guess in [
            InitialGuess::Previous,
            InitialGuess::Inertia,
            InitialGuess::InertiaAndGravity,
            InitialGuess::Adaptive,
        ] {
            let mesh = bar_mesh(UVec3::new(6, 2, 2));
            let root = end_nodes(&mesh, 0.0, -1.0);
            let material = Material {
                youngs_modulus: 1.8e5,
                poisson_ratio: nu,
                density: 1040.0,
            };
            let mut p = vbd_params(72.0, 3, 5, false, 1.0);
            p.initial_guess = guess;
            p.stiffness_damping = 1e-3;
            p.chebyshev_rho = Some(0.9);
            p.threads = 1;
            let mut s = VbdSolver::new(mesh, material, p).unwrap();
            s.pin(&root);
            for _ in 0..20 {
                s.step_frame().unwrap();
            }
            let moved = s
                .displacements()
                .iter()
                .filter(|u| u.length() != 0.0)
                .count();
            assert_eq!(moved, 0, "ν = {nu}, {guess:?}: {moved} nodes moved");
            assert_eq!(s.elastic_energy(), 0.0, "ν = {nu}, {guess:?}");
            assert!(
                s.von_mises().iter().all(|&v| v == 0.0),
                "ν = {nu}, {guess:?}"
            );
        }
    }
}
