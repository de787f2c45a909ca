//! Preconditioned conjugate gradients on node vectors (Shewchuk 1994, "An Introduction
//! to the Conjugate Gradient Method Without the Agonizing Pain", B3), truncated as in
//! truncated Newton (Nocedal & Wright 2006, Algorithm 7.1): at a direction of
//! non-positive curvature it stops with what it has, which is still a descent direction.

use glam::Vec3;

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CgReport {
    /// Matrix–vector products spent.
    pub iterations: u32,
    /// `√(rᵀz) / √(r₀ᵀz₀)` at the end.
    pub residual_ratio: f32,
    /// Stopped at a direction of non-positive curvature.
    pub negative_curvature: bool,
}

/// Σ aᵢ·bᵢ in f64.
pub fn dot(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y) as f64).sum()
}

/// Solve `A x = b` from `x = 0`, at most `max_iterations` products, until the
/// preconditioned residual falls below `tolerance` of the first. `apply` writes `A p`,
/// `precondition` writes `M⁻¹ r` (M symmetric positive definite).
pub fn pcg(
    b: &[Vec3],
    x: &mut [Vec3],
    max_iterations: u32,
    tolerance: f32,
    mut apply: impl FnMut(&[Vec3], &mut [Vec3]),
    mut precondition: impl FnMut(&[Vec3], &mut [Vec3]),
) -> CgReport {
    let n = b.len();
    x.iter_mut().for_each(|v| *v = Vec3::ZERO);
    let mut r = b.to_vec();
    let mut z = vec![Vec3::ZERO; n];
    precondition(&r, &mut z);
    let mut p = z.clone();
    let mut ap = vec![Vec3::ZERO; n];
    let mut rz = dot(&r, &z);
    let first = rz.max(f64::MIN_POSITIVE);
    let mut report = CgReport {
        residual_ratio: 1.0,
        ..CgReport::default()
    };
    while report.iterations < max_iterations && rz > 0.0 {
        if rz <= (tolerance as f64).powi(2) * first {
            break;
        }
        apply(&p, &mut ap);
        report.iterations += 1;
        let pap = dot(&p, &ap);
        if pap <= 0.0 {
            report.negative_curvature = true;
            if report.iterations == 1 {
                // No step taken yet: the preconditioned gradient is a descent direction.
                x.copy_from_slice(&p);
            }
            break;
        }
        let alpha = (rz / pap) as f32;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        precondition(&r, &mut z);
        let rz_next = dot(&r, &z);
        let beta = (rz_next / rz) as f32;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
        rz = rz_next;
        report.residual_ratio = (rz.max(0.0) / first).sqrt() as f32;
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D Laplacian (tridiagonal 2, −1 in each component) plus a diagonal shift.
    fn laplacian(p: &[Vec3], out: &mut [Vec3]) {
        let n = p.len();
        for i in 0..n {
            let left = if i > 0 { p[i - 1] } else { Vec3::ZERO };
            let right = if i + 1 < n { p[i + 1] } else { Vec3::ZERO };
            out[i] = 2.01 * p[i] - left - right;
        }
    }

    #[test]
    fn solves_a_symmetric_positive_definite_system() {
        let n = 40;
        let b: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(1.0, (i as f32).sin(), -0.5))
            .collect();
        let mut x = vec![Vec3::ZERO; n];
        let rep = pcg(&b, &mut x, 200, 1e-6, laplacian, |r, z| {
            z.iter_mut().zip(r).for_each(|(z, r)| *z = *r / 2.01)
        });
        let mut ax = vec![Vec3::ZERO; n];
        laplacian(&x, &mut ax);
        let err = ax
            .iter()
            .zip(&b)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0f32, f32::max);
        assert!(
            err < 1e-3,
            "residual {err} after {} products",
            rep.iterations
        );
        assert!(!rep.negative_curvature);
        // Exact arithmetic needs at most n products; allow rounding.
        assert!(rep.iterations <= 2 * n as u32);
    }

    #[test]
    fn stops_at_negative_curvature_with_a_descent_direction() {
        let b = vec![Vec3::ONE; 3];
        let mut x = vec![Vec3::ZERO; 3];
        let rep = pcg(
            &b,
            &mut x,
            10,
            1e-6,
            |p, out| out.iter_mut().zip(p).for_each(|(o, p)| *o = -*p),
            |r, z| z.copy_from_slice(r),
        );
        assert!(rep.negative_curvature);
        assert!(dot(&x, &b) > 0.0, "not a descent direction for −b");
    }
}
