//! Eight-lane 3-vectors and 3×3 matrices over a [`Lane`] type: the algebra of the batched tet
//! projection ([`super::rest_free_lanes`]), each lane one tet. The operations mirror
//! glam's `Vec3`/`Mat3` (column-major, the same operation order) so that a lane computes
//! what the scalar reference computes, up to the rounding of `ln`.

use std::ops::{Add, Mul, Neg, Sub};

pub use super::lane::{LANES, Lane, LaneMath};

/// A 3-vector per lane.
#[derive(Debug, Clone, Copy)]
pub struct V3<L> {
    /// x components.
    pub x: L,
    /// y components.
    pub y: L,
    /// z components.
    pub z: L,
}

impl<L: LaneMath> V3<L> {
    /// The zero vector in every lane.
    pub const ZERO: V3<L> = V3 {
        x: L::ZERO,
        y: L::ZERO,
        z: L::ZERO,
    };

    /// Dot product per lane.
    #[inline(always)]
    pub fn dot(self, o: V3<L>) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Squared length per lane.
    #[inline(always)]
    pub fn length_squared(self) -> L {
        self.dot(self)
    }

    /// Cross product per lane.
    #[inline(always)]
    pub fn cross(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }
}

impl<L: Lane> V3<L> {
    /// The vector stored component by component (`soa[c][k]`: component c of lane k):
    /// three contiguous loads.
    #[inline(always)]
    pub fn load(soa: &[[f32; LANES]; 3]) -> V3<L> {
        V3 {
            x: L::new(soa[0]),
            y: L::new(soa[1]),
            z: L::new(soa[2]),
        }
    }

    /// Lane `k` of `v` is `v[k]`.
    #[inline(always)]
    pub fn gather(v: &[glam::Vec3; LANES]) -> V3<L> {
        V3 {
            x: L::new(std::array::from_fn(|k| v[k].x)),
            y: L::new(std::array::from_fn(|k| v[k].y)),
            z: L::new(std::array::from_fn(|k| v[k].z)),
        }
    }

    /// The vector of lane `k` (tests: a pass reads all lanes from [`V3::to_arrays`]).
    #[cfg(test)]
    pub fn lane(&self, k: usize) -> glam::Vec3 {
        glam::Vec3::new(
            self.x.to_array()[k],
            self.y.to_array()[k],
            self.z.to_array()[k],
        )
    }

    /// The components as arrays (`[x, y, z][k]`: lane k), stored once so that reading
    /// every lane does not store the registers again for each.
    #[inline(always)]
    pub fn to_arrays(self) -> [[f32; LANES]; 3] {
        [self.x.to_array(), self.y.to_array(), self.z.to_array()]
    }
}

impl<L: LaneMath> Add for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn add(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl<L: LaneMath> Sub for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn sub(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl<L: LaneMath> Neg for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn neg(self) -> V3<L> {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl<L: LaneMath> Mul<L> for V3<L> {
    type Output = V3<L>;
    #[inline(always)]
    fn mul(self, s: L) -> V3<L> {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

/// A 3×3 matrix per lane, by columns.
#[derive(Debug, Clone, Copy)]
pub struct M3<L> {
    /// First column.
    pub c0: V3<L>,
    /// Second column.
    pub c1: V3<L>,
    /// Third column.
    pub c2: V3<L>,
}

impl<L: LaneMath> M3<L> {
    /// `s · I` per lane.
    #[inline(always)]
    pub fn diagonal(s: L) -> M3<L> {
        let z = L::ZERO;
        M3 {
            c0: V3 { x: s, y: z, z },
            c1: V3 { x: z, y: s, z },
            c2: V3 { x: z, y: z, z: s },
        }
    }

    /// Row `r` as a vector.
    #[inline(always)]
    fn row(&self, r: usize) -> V3<L> {
        let pick = |c: &V3<L>| match r {
            0 => c.x,
            1 => c.y,
            _ => c.z,
        };
        V3 {
            x: pick(&self.c0),
            y: pick(&self.c1),
            z: pick(&self.c2),
        }
    }

    /// Transpose per lane.
    #[inline(always)]
    pub fn transpose(&self) -> M3<L> {
        M3 {
            c0: self.row(0),
            c1: self.row(1),
            c2: self.row(2),
        }
    }

    /// Matrix × vector per lane.
    #[inline(always)]
    pub fn mul_vec(&self, v: V3<L>) -> V3<L> {
        self.c0 * v.x + self.c1 * v.y + self.c2 * v.z
    }

    /// Matrix product per lane.
    #[inline(always)]
    pub fn mul_mat(&self, o: &M3<L>) -> M3<L> {
        M3 {
            c0: self.mul_vec(o.c0),
            c1: self.mul_vec(o.c1),
            c2: self.mul_vec(o.c2),
        }
    }

    /// Determinant per lane (glam's order: `c2 · (c0 × c1)`).
    #[inline(always)]
    pub fn determinant(&self) -> L {
        self.c2.dot(self.c0.cross(self.c1))
    }

    /// Cofactor matrix `[c1×c2, c2×c0, c0×c1]` per lane.
    #[inline(always)]
    pub fn cofactor(&self) -> M3<L> {
        M3 {
            c0: self.c1.cross(self.c2),
            c1: self.c2.cross(self.c0),
            c2: self.c0.cross(self.c1),
        }
    }

    /// Trace per lane.
    #[inline(always)]
    pub fn trace(&self) -> L {
        self.c0.x + self.c1.y + self.c2.z
    }

    /// Squared Frobenius norm per lane.
    #[inline(always)]
    pub fn norm2(&self) -> L {
        self.c0.length_squared() + self.c1.length_squared() + self.c2.length_squared()
    }
}

impl<L: Lane> M3<L> {
    /// The matrix stored entry by entry, column-major (`soa[3c + r][k]`: row r of column
    /// c in lane k, as [`store_mat`] writes it): nine contiguous loads.
    #[inline(always)]
    pub fn load(soa: &[[f32; LANES]; 9]) -> M3<L> {
        let col = |c: usize| V3 {
            x: L::new(soa[3 * c]),
            y: L::new(soa[3 * c + 1]),
            z: L::new(soa[3 * c + 2]),
        };
        M3 {
            c0: col(0),
            c1: col(1),
            c2: col(2),
        }
    }

    /// Lane `k` of the result is `m[k]`.
    #[inline(always)]
    pub fn gather(m: &[glam::Mat3; LANES]) -> M3<L> {
        M3 {
            c0: V3::gather(&m.map(|a| a.x_axis)),
            c1: V3::gather(&m.map(|a| a.y_axis)),
            c2: V3::gather(&m.map(|a| a.z_axis)),
        }
    }

    /// The entries as arrays, column-major as [`M3::load`] reads them.
    #[inline(always)]
    pub fn to_arrays(self) -> [[f32; LANES]; 9] {
        let [c0, c1, c2] = [self.c0, self.c1, self.c2].map(V3::to_arrays);
        [
            c0[0], c0[1], c0[2], c1[0], c1[1], c1[2], c2[0], c2[1], c2[2],
        ]
    }
}

impl<L: LaneMath> Add for M3<L> {
    type Output = M3<L>;
    #[inline(always)]
    fn add(self, o: M3<L>) -> M3<L> {
        M3 {
            c0: self.c0 + o.c0,
            c1: self.c1 + o.c1,
            c2: self.c2 + o.c2,
        }
    }
}

impl<L: LaneMath> Sub for M3<L> {
    type Output = M3<L>;
    #[inline(always)]
    fn sub(self, o: M3<L>) -> M3<L> {
        M3 {
            c0: self.c0 - o.c0,
            c1: self.c1 - o.c1,
            c2: self.c2 - o.c2,
        }
    }
}

impl<L: LaneMath> Mul<L> for M3<L> {
    type Output = M3<L>;
    #[inline(always)]
    fn mul(self, s: L) -> M3<L> {
        M3 {
            c0: self.c0 * s,
            c1: self.c1 * s,
            c2: self.c2 * s,
        }
    }
}

/// Put `m` in lane `k` of `soa`, column-major (what [`M3::load`] reads).
pub fn store_mat(soa: &mut [[f32; LANES]; 9], k: usize, m: glam::Mat3) {
    for (e, v) in m.to_cols_array().into_iter().enumerate() {
        soa[e][k] = v;
    }
}

/// Put `v` in lane `k` of `soa` (what [`V3::load`] reads).
pub fn store_vec(soa: &mut [[f32; LANES]; 3], k: usize, v: glam::Vec3) {
    (soa[0][k], soa[1][k], soa[2][k]) = (v.x, v.y, v.z);
}

#[cfg(test)]
mod tests {
    use super::*;
    use wide::f32x8;

    type V3 = super::V3<f32x8>;
    type M3 = super::M3<f32x8>;
    use glam::{Mat3, Vec3};

    fn sample(k: usize) -> Mat3 {
        let s = 1.0 + k as f32 * 0.1;
        Mat3::from_cols_array(&[0.11, -0.05, 0.02, 0.07, -0.13, 0.04, -0.03, 0.09, 0.21]) * s
            + Mat3::IDENTITY
    }

    #[test]
    fn lanes_compute_what_glam_computes() {
        let a: [Mat3; LANES] = std::array::from_fn(sample);
        let b: [Mat3; LANES] = std::array::from_fn(|k| sample(k).transpose() * 0.5);
        let (la, lb) = (M3::gather(&a), M3::gather(&b));
        let prod = la.mul_mat(&lb);
        let tr = la.transpose();
        let cof = la.cofactor();
        for k in 0..LANES {
            let m = |x: &M3| Mat3::from_cols(x.c0.lane(k), x.c1.lane(k), x.c2.lane(k));
            assert!(m(&prod).abs_diff_eq(a[k] * b[k], 1e-6));
            assert_eq!(m(&tr), a[k].transpose());
            let c = &a[k];
            let glam_cof = Mat3::from_cols(
                c.y_axis.cross(c.z_axis),
                c.z_axis.cross(c.x_axis),
                c.x_axis.cross(c.y_axis),
            );
            assert!(m(&cof).abs_diff_eq(glam_cof, 1e-6));
            assert!((la.determinant().as_array()[k] - a[k].determinant()).abs() < 1e-6);
            let v = Vec3::new(0.3, -0.2, 0.5 + k as f32);
            let lv = V3::gather(&[v; LANES]);
            assert!(la.mul_vec(lv).lane(k).abs_diff_eq(a[k] * v, 1e-6));
        }
    }
}
