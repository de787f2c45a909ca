//! One tet's Neo-Hookean constraint pair projected (PHYSICS.md §1.2): the rest-free pair
//! ([`super::rest_free`], the default) or the seed paper's γ-shifted pair
//! ([`super::neo_hookean`]), coupled or sequential.

use glam::Vec3;

use super::neo_hookean::{
    ConstraintPair, TetProjection, TetTerms, project_coupled, project_sequential,
};
use super::rest_free::project_rest_free;

/// Project both constraints of `pair` of one tet in place (`x` holds the nodes'
/// displacements from rest, see
/// `deformation_gradient_from_displacement`); returns the
/// volume multiplier of this substep (the seed's hydrostatic stress, PHYSICS.md §1.3).
#[inline]
pub fn project_tet(
    x: &mut [Vec3; 4],
    w: &[f32; 4],
    t: &TetTerms,
    mode: TetProjection,
    pair: ConstraintPair,
) -> f32 {
    match (pair, mode) {
        (ConstraintPair::RestFree, _) => project_rest_free(x, w, t, mode),
        (ConstraintPair::GammaShifted, TetProjection::Coupled) => project_coupled(x, w, t),
        (ConstraintPair::GammaShifted, TetProjection::Sequential) => project_sequential(x, w, t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_conserves_momentum_with_equal_masses() {
        let mut x = [
            Vec3::ZERO,
            Vec3::new(1.3, 0.1, 0.0),
            Vec3::Y,
            Vec3::new(0.0, 0.2, 0.7),
        ];
        let before: Vec3 = x.iter().sum();
        for mode in [TetProjection::Coupled, TetProjection::Sequential] {
            for pair in [ConstraintPair::GammaShifted, ConstraintPair::RestFree] {
                project_tet(&mut x, &[2.0; 4], &TetTerms::uniform(0.1, 1.5), mode, pair);
            }
            let after: Vec3 = x.iter().sum();
            assert!((after - before).length() < 1e-5);
        }
    }
}
