//! The Hessian product of [`super::TetTangent`] eight tets at a time in SIMD lanes, with
//! the XPBD lanes' algebra (`crate::xpbd::lanes`): in one AVX register per value where
//! the CPU has AVX2 (detected at run time, so the portable build uses it), else in
//! `wide::f32x8`. The same operations in the same order as the scalar product
//! (`tet_evals.rs`, `scalar_product`), which stays the reference
//! (`cpu_kernel: Scalar`) and is tested equal to it up to rounding.

use glam::{Mat3, Vec3, Vec3A};

use super::rest_tet::RestTet;
use super::tet_tangent::TetTangent;
use crate::xpbd::lane_nodes::NodeLanes;
use crate::xpbd::lanes::{LANES, M3, V3, store_mat};

/// Eight tets' rest data: nodes, `Dm⁻¹` and the rest volumes (lanes past `count` are
/// padding). Matrices are stored entry by entry across the lanes, so each value is one
/// contiguous load (issue 35 item 2). The shape gradients `b_a` (a = 1, 2, 3) are the
/// rows of `Dm⁻¹` and are read from it: a product streams these arrays for every tet,
/// and storing `V b_a` as well made them 60 % larger.
#[derive(Debug, Clone, Copy)]
pub struct RestLanes {
    pub(super) nodes: [[u32; 4]; LANES],
    pub(super) count: usize,
    pub(super) dm_inv: [[f32; LANES]; 9],
    /// Rest volumes (0 in padding lanes).
    pub(super) volume: [f32; LANES],
}

/// Eight tets' tangents at the current iterate: `F`, `cof F`, μ, c, s₃ (stored entry by
/// entry across the lanes).
#[derive(Debug, Clone, Copy)]
pub struct TangentLanes {
    pub(super) f: [[f32; LANES]; 9],
    pub(super) cof: [[f32; LANES]; 9],
    pub(super) scalars: [[f32; LANES]; 3],
}

impl TangentLanes {
    /// Lane `k`'s tangent.
    pub fn tangent(&self, k: usize) -> TetTangent {
        let entry =
            |m: &[[f32; LANES]; 9]| Mat3::from_cols_array(&std::array::from_fn(|e| m[e][k]));
        let [mu, c, s3] = self.scalars.map(|s| s[k]);
        TetTangent::from_parts(entry(&self.f), entry(&self.cof), mu, c, s3)
    }
}

/// The rest data of `tets` in chunks of eight.
pub fn rest_lanes(tets: &[RestTet]) -> Vec<RestLanes> {
    tets.chunks(LANES)
        .map(|t| {
            let mut r = RestLanes {
                nodes: [[0; 4]; LANES],
                count: t.len(),
                dm_inv: [[0.0; LANES]; 9],
                volume: [0.0; LANES],
            };
            for (k, tet) in t.iter().enumerate() {
                r.nodes[k] = tet.nodes;
                r.volume[k] = tet.volume;
                store_mat(&mut r.dm_inv, k, tet.dm_inv);
            }
            r
        })
        .collect()
}

/// `V b_a` per lane for a = 1, 2, 3: row `a − 1` of `Dm⁻¹` (`vbd::shape_gradients`), times
/// the rest volume, as the scalar product forms it.
#[inline(always)]
fn volume_gradients<L: NodeLanes>(rest: &RestLanes) -> [V3<L>; 3] {
    let (d, v) = (&rest.dm_inv, L::new(rest.volume));
    // Written out, not a closure (see forces_in).
    [
        V3 {
            x: L::new(d[0]) * v,
            y: L::new(d[3]) * v,
            z: L::new(d[6]) * v,
        },
        V3 {
            x: L::new(d[1]) * v,
            y: L::new(d[4]) * v,
            z: L::new(d[7]) * v,
        },
        V3 {
            x: L::new(d[2]) * v,
            y: L::new(d[5]) * v,
            z: L::new(d[8]) * v,
        },
    ]
}

/// The tangents `t(0..n)` (n ≤ 8) in lanes; the lanes past `n` are unused.
pub fn tangent_lanes(n: usize, t: impl Fn(usize) -> TetTangent) -> TangentLanes {
    let mut out = TangentLanes {
        f: [[0.0; LANES]; 9],
        cof: [[0.0; LANES]; 9],
        scalars: [[0.0; LANES]; 3],
    };
    for k in 0..LANES {
        store_mat(&mut out.f, k, Mat3::IDENTITY);
        store_mat(&mut out.cof, k, Mat3::IDENTITY);
    }
    for k in 0..n {
        let (f, cof, mu, c, s3) = t(k).parts();
        store_mat(&mut out.f, k, f);
        store_mat(&mut out.cof, k, cof);
        (out.scalars[0][k], out.scalars[1][k], out.scalars[2][k]) = (mu, c, s3);
    }
    out
}

/// Add the four nodal forces `V dP[dF] b_a` of each live tet of the chunk for the
/// direction `p` to `sums` (per node; lane by lane, corner by corner, as the scalar
/// product adds them).
pub fn product_add(
    rest: &RestLanes,
    tan: &TangentLanes,
    live: &[bool],
    p: &[Vec3],
    sums: &mut [Vec3A],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { product_avx2(rest, tan, live, p, sums) };
    }
    product_in::<wide::f32x8>(rest, tan, live, p, sums);
}

/// [`product_in`] with AVX lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn product_avx2(
    rest: &RestLanes,
    tan: &TangentLanes,
    live: &[bool],
    p: &[Vec3],
    sums: &mut [Vec3A],
) {
    product_in::<crate::xpbd::lane_avx::Avx>(rest, tan, live, p, sums);
}

/// The product in lanes of type `L`, compiled into its caller; each value stored once,
/// then read lane by lane (a transpose in shuffles was no faster: 0.50 against 0.45 ms
/// serial on the intestine).
#[inline(always)]
fn product_in<L: NodeLanes>(
    rest: &RestLanes,
    tan: &TangentLanes,
    live: &[bool],
    p: &[Vec3],
    sums: &mut [Vec3A],
) {
    let [f0, f1, f2, f3] = forces_in::<L>(rest, tan, p);
    let f = [
        f0.to_arrays(),
        f1.to_arrays(),
        f2.to_arrays(),
        f3.to_arrays(),
    ];
    for k in (0..rest.count).filter(|&k| live[k]) {
        for a in 0..4 {
            sums[rest.nodes[k][a] as usize] += Vec3A::new(f[a][0][k], f[a][1][k], f[a][2][k]);
        }
    }
}

/// `p` at the chunk's four corners, lane by lane (zero in padding lanes).
#[inline(always)]
pub(super) fn corners<L: NodeLanes>(rest: &RestLanes, p: &[Vec3]) -> [V3<L>; 4] {
    let corner = |a: usize| -> [u32; LANES] { std::array::from_fn(|k| rest.nodes[k][a]) };
    // Written out, not `map` (see forces_in).
    [
        L::read_vec3s(p, &corner(0), rest.count),
        L::read_vec3s(p, &corner(1), rest.count),
        L::read_vec3s(p, &corner(2), rest.count),
        L::read_vec3s(p, &corner(3), rest.count),
    ]
}

/// The chunk's four nodal forces per lane in lanes of type `L`, compiled into its caller
/// (loops written out: an out-of-line closure would be compiled without the caller's AVX).
#[inline(always)]
fn forces_in<L: NodeLanes>(rest: &RestLanes, tan: &TangentLanes, p: &[Vec3]) -> [V3<L>; 4] {
    let [d0, d1, d2, d3] = corners::<L>(rest, p);
    let ds = M3 {
        c0: d1 - d0,
        c1: d2 - d0,
        c2: d3 - d0,
    };
    let df = ds.mul_mat(&M3::load(&rest.dm_inv));
    let (f, cof) = (M3::<L>::load(&tan.f), M3::<L>::load(&tan.cof));
    let (mu, c, s3) = (
        L::new(tan.scalars[0]),
        L::new(tan.scalars[1]),
        L::new(tan.scalars[2]),
    );
    let dj = cof.c0.dot(df.c0) + cof.c1.dot(df.c1) + cof.c2.dot(df.c2);
    let dcof = M3 {
        c0: df.c1.cross(f.c2) + f.c1.cross(df.c2),
        c1: df.c2.cross(f.c0) + f.c2.cross(df.c0),
        c2: df.c0.cross(f.c1) + f.c0.cross(df.c1),
    };
    let dp = df * mu + cof * (c * dj) + dcof * s3;
    let [vb1, vb2, vb3] = volume_gradients::<L>(rest);
    let f1 = dp.mul_vec(vb1);
    let f2 = dp.mul_vec(vb2);
    let f3 = dp.mul_vec(vb3);
    let f0 = -(f1 + f2 + f3);
    [f0, f1, f2, f3]
}
