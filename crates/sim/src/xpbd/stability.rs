//! The substep stability bound of the Neo-Hookean constraints.
//!
//! With `C_D = ‖F‖` and `C_H = det F − γ` both constraints carry a multiplier of order
//! `μ V h²` at rest (their forces cancel, PHYSICS.md §1.2), so every substep applies a
//! geometric stiffness of order μ explicitly. That is stable only while the dimensionless
//! *stiffness number* of each tet,
//!
//! ```text
//! κ = h² μ V Σ_i w_i |∇_i|²,   ∇_1..3 = columns of Dm⁻ᵀ, ∇_0 = −Σ ∇_1..3,
//! ```
//!
//! (the shear wave's substep crossing, `(h c / ℓ)²` up to a shape factor) stays below about
//! one. Measured on a 6×3×2 block at ν = 0.3/0.45/0.49: κ ≤ 0.92 stays at rest to 1e-9 m
//! over 300 frames, κ ≥ 1.6 drifts by 1e-4 m to centimetres (see docs/physics-notes.md).
//! The solver refuses settings above [`MAX_STIFFNESS_NUMBER`] and says how many substeps
//! would do. The bound holds for the rest-free pair too: it has no tension at rest, but a
//! loaded tissue carries stress of the same order, and one Gauss–Seidel sweep per substep
//! is accurate only for κ ≲ 1 (a cantilever sags 2× too far at κ = 11 and explodes at
//! κ = 126; docs/physics-notes.md).

use glam::Vec3;

use crate::material::Lame;
use crate::mesh::TetMesh;

/// Largest stiffness number the solver accepts.
pub const MAX_STIFFNESS_NUMBER: f32 = 1.0;

/// The worst tet's stiffness number κ for substep `h`, and that tet.
// PHYSICS.md §1.2: S = Σ w |∇C|², α̃ = 1/(μ V h²); κ = S / α̃ for ∂C/∂F = I.
pub fn stiffness_number(mesh: &TetMesh, inv_mass: &[f32], lame: Lame, h: f32) -> (f32, usize) {
    let mut worst = (0.0f32, 0);
    for (t, tet) in mesh.tets.iter().enumerate() {
        let g = mesh.dm_inv[t].transpose();
        let grads: [Vec3; 4] = [
            -(g.x_axis + g.y_axis + g.z_axis),
            g.x_axis,
            g.y_axis,
            g.z_axis,
        ];
        let s: f32 = (0..4)
            .map(|i| inv_mass[tet[i] as usize] * grads[i].length_squared())
            .sum();
        let k = s * h * h * lame.mu * mesh.rest_volume[t];
        if k > worst.0 {
            worst = (k, t);
        }
    }
    worst
}

/// Substeps per frame needed to bring `kappa` (measured at `substeps`) to the bound.
pub fn substeps_needed(kappa: f32, substeps: u32) -> u32 {
    // κ ∝ h², so the substep count scales with √κ.
    (substeps as f32 * (kappa / MAX_STIFFNESS_NUMBER).sqrt()).ceil() as u32
}
