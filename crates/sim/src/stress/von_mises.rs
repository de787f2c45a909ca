//! Cauchy stress σ_T (seed eq. 3) and von Mises stress (seed eq. 4) of one tet.

use glam::{Mat3, Quat};

use super::extract_rotation;

/// Stress state of one tet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetStress {
    /// von Mises stress `σ_vM = sqrt(3/2) ‖dev σ_T‖_F`, Pa.
    pub von_mises: f32,
    /// Mean normal stress `tr(σ_T)/3`, Pa.
    pub mean: f32,
    /// Rotation of the polar decomposition (for warm-starting the next frame).
    pub rotation: Quat,
}

/// `σ_T = μ((RᵀF + FᵀR)/2 − I) + λ_H/(h² V) I`, `σ_vM = sqrt(3/2)‖σ_T − tr(σ_T)/3 I‖_F`.
///
/// `lambda_h` is the tet's hydrostatic multiplier of the last substep, `h2` the squared
/// substep, `rest_volume` V; `warm` is the previous rotation.
// PHYSICS.md §1.3, seed eqs. (3) and (4).
pub fn tet_stress(
    f: &Mat3,
    mu: f32,
    lambda_h: f32,
    h2: f32,
    rest_volume: f32,
    warm: Quat,
) -> TetStress {
    let q = extract_rotation(f, warm, 20);
    let r = Mat3::from_quat(q);
    let rtf = r.transpose() * *f;
    let sym = (rtf + rtf.transpose()) * 0.5;
    let sigma_h = lambda_h / (h2 * rest_volume);
    // σ_T = μ(S − I) + σ_H I. The isotropic parts cancel in the deviator, so
    // dev σ_T = μ dev S exactly; computing it that way avoids subtracting a large pressure
    // from itself in f32 (PHYSICS.md §1.3: σ_vM = μ sqrt(3/2) ‖dev S‖_F).
    let tr_s = sym.x_axis.x + sym.y_axis.y + sym.z_axis.z;
    let mean = mu * (tr_s / 3.0 - 1.0) + sigma_h;
    let dev = (sym - Mat3::IDENTITY * (tr_s / 3.0)) * mu;
    let norm2 =
        dev.x_axis.length_squared() + dev.y_axis.length_squared() + dev.z_axis.length_squared();
    TetStress {
        von_mises: (1.5 * norm2).sqrt(),
        mean,
        rotation: q,
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// Validation test 1 of the foundation issue: uniaxial stretch F = diag(s,1,1) gives
    /// σ_vM = μ|s − 1| to 1e-5 relative, whatever the hydrostatic multiplier.
    #[test]
    fn uniaxial_stretch_matches_closed_form() {
        let mu = 3.4e3;
        for s in [0.5f32, 0.8, 0.99, 1.01, 1.25, 2.0, 3.0] {
            let f = Mat3::from_diagonal(Vec3::new(s, 1.0, 1.0));
            for lambda_h in [0.0, 1e-9, -3e-8] {
                let st = tet_stress(&f, mu, lambda_h, 1e-6, 1e-8, Quat::IDENTITY);
                let expect = mu * (s - 1.0).abs();
                let rel = (st.von_mises - expect).abs() / expect;
                assert!(
                    rel < 1e-5,
                    "s={s}: {} vs {expect} (rel {rel})",
                    st.von_mises
                );
            }
        }
    }

    #[test]
    fn rotation_does_not_change_von_mises() {
        let mu = 1.0e4;
        let f = Mat3::from_diagonal(Vec3::new(1.3, 0.9, 1.0));
        let r = Mat3::from_quat(Quat::from_axis_angle(
            Vec3::new(0.3, 1.0, 0.2).normalize(),
            2.0,
        ));
        let a = tet_stress(&f, mu, 0.0, 1.0, 1.0, Quat::IDENTITY).von_mises;
        let b = tet_stress(&(r * f), mu, 0.0, 1.0, 1.0, Quat::IDENTITY).von_mises;
        assert!((a - b).abs() / a < 1e-5, "{a} vs {b}");
    }
}
