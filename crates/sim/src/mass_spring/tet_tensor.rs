//! The stiffness a tet's springs give it, as a tensor, and the spring constants that give
//! a tet a wanted tensor (docs/physics-notes.md, "Nakao": split edges and stiffness).
//!
//! Under a small uniform strain ε a spring along unit direction n with constant k and
//! length d stores `½ k d² (nᵀεn)²`, so a tet's six springs store `½ ε:T:ε` with the
//! fully symmetric fourth-order tensor `T = Σ_e β_e n_e⊗n_e⊗n_e⊗n_e`, `β_e = k_e d_e²`.
//! Per unit volume, `T/V` is the material stiffness the tet carries; the pre-stress of
//! the tension of eq. 3 is its contraction `T:I/V` times s. When a tet is split or its
//! nodes move, its pieces keep that material: their constants are the non-negative least
//! squares fit of `V_piece · T/V` onto their own edge directions.

use glam::DVec3;

use crate::mesh::TET_EDGES;

/// Exponents (a, b, c), a + b + c = 4, of the 15 distinct components of a symmetric
/// fourth-order tensor in 3-D, and their multiplicities 4!/(a! b! c!).
const MONOMIALS: [([i32; 3], f64); 15] = [
    ([4, 0, 0], 1.0),
    ([0, 4, 0], 1.0),
    ([0, 0, 4], 1.0),
    ([3, 1, 0], 4.0),
    ([3, 0, 1], 4.0),
    ([1, 3, 0], 4.0),
    ([0, 3, 1], 4.0),
    ([1, 0, 3], 4.0),
    ([0, 1, 3], 4.0),
    ([2, 2, 0], 6.0),
    ([2, 0, 2], 6.0),
    ([0, 2, 2], 6.0),
    ([2, 1, 1], 12.0),
    ([1, 2, 1], 12.0),
    ([1, 1, 2], 12.0),
];

fn monomial(n: DVec3, e: [i32; 3]) -> f64 {
    n.x.powi(e[0]) * n.y.powi(e[1]) * n.z.powi(e[2])
}

/// A tet's spring stiffness per unit volume, `Σ_e β_e n_e⁴ / V` (15 components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetTensor([f64; 15]);

/// Unit directions and lengths of the six edges of the tet with corners `p`
/// ([`TET_EDGES`] order).
pub(crate) fn edge_frames(p: [DVec3; 4]) -> [(DVec3, f64); 6] {
    TET_EDGES.map(|(a, b)| {
        let e = p[b] - p[a];
        let d = e.length();
        (if d > 0.0 { e / d } else { DVec3::ZERO }, d)
    })
}

impl TetTensor {
    /// The tensor per unit volume of springs with constants `k` on a tet of volume
    /// `volume` whose edges are `frames`.
    pub(crate) fn of_springs(frames: &[(DVec3, f64); 6], k: &[f64; 6], volume: f64) -> Self {
        let mut t = [0.0; 15];
        for (&(n, d), &k) in frames.iter().zip(k) {
            for (c, (e, _)) in t.iter_mut().zip(MONOMIALS) {
                *c += k * d * d * monomial(n, e) / volume;
            }
        }
        TetTensor(t)
    }

    /// The full contraction `T_iijj` per unit volume (`Σ β / V`).
    fn contraction(&self) -> f64 {
        let c = &self.0;
        c[0] + c[1] + c[2] + 2.0 * (c[9] + c[10] + c[11])
    }

    /// `T(m, m, m, m)` per unit volume.
    fn along(&self, m: DVec3) -> f64 {
        self.0
            .iter()
            .zip(MONOMIALS)
            .map(|(c, (e, w))| c * w * monomial(m, e))
            .sum()
    }

    /// The non-negative spring constants of a tet of volume `volume` with edges `frames`
    /// that best give it `volume · self` (least squares in the Frobenius norm);
    /// `start` is a first guess (the tet's constants before the change).
    pub(crate) fn fit(&self, frames: &[(DVec3, f64); 6], volume: f64, start: [f64; 6]) -> [f64; 6] {
        // Normal equations in β = k d²: G β = b, G_ij = (n_i·n_j)⁴, b_i = V T(n_i⁴).
        let mut g = [[0.0; 6]; 6];
        let mut b = [0.0; 6];
        for i in 0..6 {
            for j in 0..6 {
                g[i][j] = frames[i].0.dot(frames[j].0).powi(4);
            }
            b[i] = volume * self.along(frames[i].0);
        }
        let beta = solve6(g, b)
            .filter(|x| x.iter().all(|&v| v >= 0.0))
            .unwrap_or_else(|| {
                let guess = std::array::from_fn(|i| start[i] * frames[i].1 * frames[i].1);
                nonnegative_least_squares(&g, &b, guess)
            });
        // The fit is a projection and loses magnitude where the new shape cannot carry the
        // old directions; scale it so that the full contraction T_iijj = Σ β (the mean
        // stiffness over all directions) is kept.
        let total: f64 = beta.iter().sum();
        let want = volume * self.contraction();
        let beta = if total > 0.0 && want > 0.0 {
            beta.map(|x| x * want / total)
        } else {
            beta
        };
        std::array::from_fn(|i| {
            let d = frames[i].1;
            if d > 0.0 { beta[i] / (d * d) } else { 0.0 }
        })
    }
}

/// Solve the 6 × 6 system `g x = b` by Gaussian elimination with partial pivoting;
/// `None` when it is singular.
fn solve6(mut g: [[f64; 6]; 6], mut b: [f64; 6]) -> Option<[f64; 6]> {
    let scale = g.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for c in 0..6 {
        let p = (c..6).max_by(|&i, &j| g[i][c].abs().total_cmp(&g[j][c].abs()))?;
        if g[p][c].abs() <= 1e-12 * scale {
            return None;
        }
        g.swap(c, p);
        b.swap(c, p);
        let pivot = g[c];
        for r in c + 1..6 {
            let f = g[r][c] / pivot[c];
            for (x, p) in g[r].iter_mut().zip(pivot).skip(c) {
                *x -= f * p;
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 6];
    for r in (0..6).rev() {
        let s: f64 = (r + 1..6).map(|k| g[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / g[r][r];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Minimise `½ xᵀ g x − bᵀ x` over `x ≥ 0` by projected Gauss–Seidel from `x`.
fn nonnegative_least_squares(g: &[[f64; 6]; 6], b: &[f64; 6], mut x: [f64; 6]) -> [f64; 6] {
    for v in &mut x {
        *v = if v.is_finite() { v.max(0.0) } else { 0.0 };
    }
    for _ in 0..500 {
        for i in 0..6 {
            if g[i][i] <= 0.0 {
                continue;
            }
            let r: f64 = b[i] - (0..6).map(|j| g[i][j] * x[j]).sum::<f64>();
            x[i] = (x[i] + r / g[i][i]).max(0.0);
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corner() -> [DVec3; 4] {
        [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
    }

    #[test]
    fn fitting_a_tets_own_tensor_gives_back_its_springs() {
        let f = edge_frames(corner());
        let k = [10.0, 20.0, 30.0, 15.0, 25.0, 35.0];
        let t = TetTensor::of_springs(&f, &k, 1.0 / 6.0);
        let back = t.fit(&f, 1.0 / 6.0, [1.0; 6]);
        for (a, b) in k.iter().zip(back) {
            assert!((a - b).abs() < 1e-9 * a, "{k:?} vs {back:?}");
        }
    }

    #[test]
    fn strain_energy_of_the_tensor_is_the_springs_energy() {
        let f = edge_frames(corner());
        let k = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let t = TetTensor::of_springs(&f, &k, 1.0);
        let m = DVec3::new(0.3, -0.5, 0.8).normalize();
        // A stretch along m: each spring's strain is (n·m)², its energy ½ k d² (n·m)⁴.
        let springs: f64 = f
            .iter()
            .zip(k)
            .map(|(&(n, d), k)| k * d * d * n.dot(m).powi(4))
            .sum();
        assert!((t.along(m) - springs).abs() < 1e-12);
    }

    #[test]
    fn an_infeasible_fit_stays_non_negative() {
        let f = edge_frames(corner());
        let t = TetTensor::of_springs(&f, &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0], 1.0);
        let skew = edge_frames([DVec3::ZERO, DVec3::X, DVec3::new(0.2, 1.0, 0.0), DVec3::Z]);
        let k = t.fit(&skew, 1.0, [0.0; 6]);
        assert!(k.iter().all(|&v| v >= 0.0), "{k:?}");
    }
}
