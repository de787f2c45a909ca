//! Rotation extraction by Müller et al. 2016, "A Robust Method to Extract the Rotational
//! Part of Deformations": iterate `q ← exp(ω) q` with
//! `ω = Σ r_i × a_i / (|Σ r_i · a_i| + ε)` (r_i, a_i the columns of R and A).
//! Warm-started from the previous frame's rotation it converges in a few iterations,
//! stays a proper rotation for inverted tets, and maps directly onto a GPU kernel.

use glam::{Mat3, Quat};

/// Rotation `R` of the polar decomposition `A = R S`, starting from `q` (warm start).
// PHYSICS.md §1.3, polar decomposition (Müller et al. 2016, Alg. 1).
pub fn extract_rotation(a: &Mat3, mut q: Quat, max_iterations: u32) -> Quat {
    for _ in 0..max_iterations {
        let r = Mat3::from_quat(q);
        let num = r.x_axis.cross(a.x_axis) + r.y_axis.cross(a.y_axis) + r.z_axis.cross(a.z_axis);
        let den = (r.x_axis.dot(a.x_axis) + r.y_axis.dot(a.y_axis) + r.z_axis.dot(a.z_axis)).abs()
            + 1.0e-9;
        let omega = num * (1.0 / den);
        let angle = omega.length();
        if angle < 1.0e-9 {
            break;
        }
        q = (Quat::from_axis_angle(omega / angle, angle) * q).normalize();
    }
    q
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn recovers_rotation_of_rotated_stretch() {
        let r = Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
        let s = Mat3::from_cols_array(&[1.2, 0.1, 0.0, 0.1, 0.9, 0.05, 0.0, 0.05, 1.05]);
        let a = Mat3::from_quat(r) * s;
        let q = extract_rotation(&a, Quat::IDENTITY, 50);
        assert!(q.dot(r).abs() > 1.0 - 1e-6, "{q} vs {r}");
    }

    #[test]
    fn symmetric_stretch_has_identity_rotation() {
        let a = Mat3::from_diagonal(Vec3::new(1.7, 1.0, 1.0));
        assert_eq!(extract_rotation(&a, Quat::IDENTITY, 20), Quat::IDENTITY);
    }
}
