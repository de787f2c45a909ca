//! The implicit step's two-level preconditioner: block Jacobi (or one symmetric block
//! Gauss–Seidel sweep, [`BlockMatrix`]) plus the coarse-grid correction `P A_c⁻¹ Pᵀ`
//! ([`CoarseLevel`]), added.

use glam::{Mat3, Vec3, Vec3A};

use super::block_matrix::BlockMatrix;
use super::coarse_level::CoarseLevel;
use super::tet_evals::for_each;
use crate::thread_team::ThreadTeam;

/// Block Jacobi plus the coarse correction.
pub(super) struct TwoLevel {
    /// Each node's inverted diagonal block of `∇²G` (zero at fixed nodes).
    pub(super) diag_inv: Vec<Mat3>,
    /// The coarse grid, its matrix and factor.
    pub(super) level: CoarseLevel,
    /// The assembled Hessian for the Gauss–Seidel smoother (`None`: block Jacobi).
    pub(super) matrix: Option<BlockMatrix>,
    /// The coarse right-hand side and solution (f64, three per coarse node).
    pub(super) rhs: Vec<f64>,
    /// The coarse solution in f32 (each value rounded once), what the fine nodes read.
    pub(super) coarse: Vec<Vec3A>,
}

impl TwoLevel {
    /// `z = S r + P A_c⁻¹ Pᵀ r` (additive two-level; zero at fixed nodes), `S` one
    /// symmetric Gauss–Seidel sweep where the smoother is `GaussSeidel` and `smooth`, else
    /// block Jacobi `D⁻¹`; the fine part, the prolongation and the mask in one node pass.
    pub(super) fn apply(
        &mut self,
        r: &[Vec3],
        z: &mut [Vec3],
        free: &[bool],
        team: Option<&ThreadTeam>,
        smooth: bool,
    ) {
        let level = &self.level;
        level.grid.restrict(r, &mut self.rhs, team);
        level.system.solve(&mut self.rhs);
        self.coarse.clear();
        self.coarse.extend(
            self.rhs
                .chunks_exact(3)
                .map(|v| Vec3A::new(v[0] as f32, v[1] as f32, v[2] as f32)),
        );
        let smoothed = match (&self.matrix, smooth) {
            (Some(m), true) => {
                m.symmetric_gauss_seidel(r, z, free);
                true
            }
            _ => false,
        };
        let (grid, coarse, diag_inv) = (&level.grid, &self.coarse, &self.diag_inv);
        for_each(team, z, |i, z| {
            *z = if !free[i] {
                Vec3::ZERO
            } else {
                let fine = if smoothed { *z } else { diag_inv[i] * r[i] };
                grid.add_prolonged(i, coarse, fine.into()).into()
            };
        });
    }
}
