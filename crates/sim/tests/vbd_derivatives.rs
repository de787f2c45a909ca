//! VBD: the per-vertex gradient and 3×3 Hessian block of a tet's energy
//! (`incise_sim::vbd::vertex_gradient_hessian`) match central finite differences of an
//! independent f64 evaluation of `V Ψ`, `Ψ = μ/2 (I_C − 3) − μ L(J) + λ/2 L(J)²` (with the
//! linear continuation of `ln J` below `J_MIN`), for all four vertices, at moderate
//! strain, large strain, and in the continued region; where the exact block is indefinite
//! the projected block stays SPD.

use glam::{Mat3, Vec3};
use incise_sim::Material;
use incise_sim::vbd::{energy_density, vertex_gradient_hessian};
use incise_sim::xpbd::{J_MIN, Strain, displacement_gradient};

type V3 = [f64; 3];

/// f64 energy `V Ψ` of a tet with rest corners `rest` and deformed corners `x`.
#[allow(clippy::needless_range_loop)] // index loops over 3×3 matrices read as the formulas
fn energy64(rest: &[V3; 4], x: &[V3; 4], mu: f64, lambda: f64) -> f64 {
    let sub = |a: V3, b: V3| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cols = |p: &[V3; 4]| [sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])];
    let det = |c: [V3; 3]| {
        c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
            - c[1][0] * (c[0][1] * c[2][2] - c[0][2] * c[2][1])
            + c[2][0] * (c[0][1] * c[1][2] - c[0][2] * c[1][1])
    };
    let dm = cols(rest);
    let ds = cols(x);
    // Dm⁻¹ by cofactors (columns of dm are the rest edges).
    let d = det(dm);
    let m = |r: usize, c: usize| dm[c][r];
    let mut inv = [[0.0f64; 3]; 3]; // inv[r][c]
    for r in 0..3 {
        for c in 0..3 {
            let (r1, r2) = ((c + 1) % 3, (c + 2) % 3);
            let (c1, c2) = ((r + 1) % 3, (r + 2) % 3);
            inv[r][c] = (m(r1, c1) * m(r2, c2) - m(r1, c2) * m(r2, c1)) / d;
        }
    }
    // F = Ds Dm⁻¹ (F[r][c]).
    let mut f = [[0.0f64; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            f[r][c] = (0..3).map(|k| ds[k][r] * inv[k][c]).sum();
        }
    }
    let fcols = [
        [f[0][0], f[1][0], f[2][0]],
        [f[0][1], f[1][1], f[2][1]],
        [f[0][2], f[1][2], f[2][2]],
    ];
    let j = det(fcols);
    let ic: f64 = f.iter().flatten().map(|v| v * v).sum();
    let jmin = J_MIN as f64;
    let l = if j > jmin {
        j.ln()
    } else {
        jmin.ln() + (j - jmin) / jmin
    };
    let psi = 0.5 * mu * (ic - 3.0) - mu * l + 0.5 * lambda * l * l;
    psi * d.abs() / 6.0
}

fn check(x_f32: [Vec3; 4], label: &str, expect_exact: bool) {
    let rest_f32 = [
        Vec3::ZERO,
        Vec3::new(0.01, 0.0, 0.0),
        Vec3::new(0.002, 0.009, 0.0),
        Vec3::new(0.003, 0.002, 0.011),
    ];
    let m = Material {
        youngs_modulus: 1.8e5,
        poisson_ratio: 0.45,
        density: 1040.0,
    };
    let lame = m.lame();
    let (mu, lambda) = (lame.mu as f64, lame.lambda as f64);
    let dm = Mat3::from_cols(
        rest_f32[1] - rest_f32[0],
        rest_f32[2] - rest_f32[0],
        rest_f32[3] - rest_f32[0],
    );
    let dm_inv = dm.inverse();
    let volume = dm.determinant().abs() / 6.0;
    let u: [Vec3; 4] = std::array::from_fn(|k| x_f32[k] - rest_f32[k]);
    let s = Strain::of(displacement_gradient(&u, &dm_inv));
    let to64 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let rest = rest_f32.map(to64);
    let x = x_f32.map(to64);
    let e = energy64(&rest, &x, mu, lambda);
    let e32 = (volume * energy_density(&s, lame)) as f64;
    assert!(
        (e32 - e).abs() <= 1e-4 * e.abs() + 1e-12,
        "{label}: energy {e32} vs {e}"
    );
    let b = incise_sim::vbd::shape_gradients(&dm_inv);
    let eps = 1e-6;
    for a in 0..4 {
        let (g, hb) = vertex_gradient_hessian(&s, lame, volume, b[a]);
        let shifted = |d: [f64; 3]| {
            let mut y = x;
            for k in 0..3 {
                y[a][k] += d[k];
            }
            energy64(&rest, &y, mu, lambda)
        };
        let unit = |k: usize, h: f64| {
            let mut d = [0.0; 3];
            d[k] = h;
            d
        };
        let scale_g = g.length() as f64 + 1e-9;
        for k in 0..3 {
            let fd = (shifted(unit(k, eps)) - shifted(unit(k, -eps))) / (2.0 * eps);
            assert!(
                (fd - g[k] as f64).abs() < 2e-3 * scale_g,
                "{label}: vertex {a} grad[{k}] {} vs fd {fd}",
                g[k]
            );
        }
        let scale_h = (0..3).map(|c| hb.col(c).length()).fold(0.0f32, f32::max) as f64;
        let eh = 1e-5;
        for r in 0..3 {
            for c in 0..3 {
                let add = |p: [f64; 3], q: [f64; 3]| [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
                let fd = (shifted(add(unit(r, eh), unit(c, eh)))
                    - shifted(add(unit(r, eh), unit(c, -eh)))
                    - shifted(add(unit(r, -eh), unit(c, eh)))
                    + shifted(add(unit(r, -eh), unit(c, -eh))))
                    / (4.0 * eh * eh);
                let got = hb.col(c)[r] as f64;
                if expect_exact {
                    assert!(
                        (fd - got).abs() < 2e-3 * scale_h,
                        "{label}: vertex {a} H[{r}][{c}] {got} vs fd {fd}"
                    );
                }
            }
        }
        // The projected block is SPD in every case.
        let det = hb.determinant();
        assert!(
            det > 0.0 && hb.x_axis.x > 0.0,
            "{label}: vertex {a} block not SPD, det {det}"
        );
    }
}

#[test]
fn gradient_and_hessian_match_finite_differences() {
    let rest = [
        Vec3::ZERO,
        Vec3::new(0.01, 0.0, 0.0),
        Vec3::new(0.002, 0.009, 0.0),
        Vec3::new(0.003, 0.002, 0.011),
    ];
    // Moderate strain (J ≈ 1.1), then large shear and stretch (J ≈ 1.6).
    let moderate = [
        rest[0] + Vec3::new(0.0003, -0.0002, 0.0001),
        rest[1] + Vec3::new(0.001, 0.0004, -0.0002),
        rest[2] + Vec3::new(-0.0005, 0.0008, 0.0003),
        rest[3] + Vec3::new(0.0002, -0.0001, 0.0009),
    ];
    check(moderate, "moderate", true);
    let large = [
        rest[0],
        rest[1] + Vec3::new(0.01, 0.002, 0.0),
        rest[2] + Vec3::new(0.004, 0.002, 0.001),
        rest[3] + Vec3::new(-0.003, 0.001, 0.002),
    ];
    check(large, "large", true);
    // Compressed to J < J_MIN: the continued branch (L'' = 0).
    let crushed = [rest[0], rest[1], rest[2], Vec3::new(0.003, 0.002, 0.0008)];
    check(crushed, "crushed", true);
}

/// At J ≈ 4.5 > e^{1+μ/λ} the exact block is indefinite; the projection keeps it SPD
/// (the gradient is still exact).
#[test]
fn projected_block_is_spd_at_large_dilation() {
    let rest = [
        Vec3::ZERO,
        Vec3::new(0.01, 0.0, 0.0),
        Vec3::new(0.002, 0.009, 0.0),
        Vec3::new(0.003, 0.002, 0.011),
    ];
    let grown = rest.map(|p| p * 1.65);
    check(grown, "dilated", false);
}
