//! The node blocks of eight tets' Hessians at once in SIMD lanes, for the assembled
//! Hessian ([`super::block_matrix`]): `pair_block` of `coarse_assembly.rs` written out per
//! entry with the shape gradients `b_a` in place of the coarse `β_j`, as the coarse
//! refresh's lanes do. In AVX registers where the CPU has AVX2 (detected at run time),
//! else in `wide::f32x8`; the scalar `pair_block` stays the reference.

use super::product_lanes::{RestLanes, TangentLanes};
use crate::xpbd::lanes::{LANES, Lane, M3, V3};

/// The pairs `(a, k)`, `a ≤ k`, of a tet's corners, in the order [`tet_blocks`] returns
/// their blocks.
pub const PAIRS: [(usize, usize); 10] = [
    (0, 0),
    (0, 1),
    (0, 2),
    (0, 3),
    (1, 1),
    (1, 2),
    (1, 3),
    (2, 2),
    (2, 3),
    (3, 3),
];

/// The ten blocks `V K_ak` (pairs [`PAIRS`]) of each tet of the chunk, entries row-major
/// per lane; with `definite` the indefinite parts cut as `BlockMatrix::assemble` says.
pub fn tet_blocks(rest: &RestLanes, tan: &TangentLanes, definite: bool) -> [[[f32; LANES]; 9]; 10] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { tet_blocks_avx2(rest, tan, definite) };
    }
    tet_blocks_in::<wide::f32x8>(rest, tan, definite)
}

/// [`tet_blocks_in`] with AVX lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn tet_blocks_avx2(
    rest: &RestLanes,
    tan: &TangentLanes,
    definite: bool,
) -> [[[f32; LANES]; 9]; 10] {
    tet_blocks_in::<crate::xpbd::lane_avx::Avx>(rest, tan, definite)
}

/// The blocks in lanes of type `L` (loops written out: an out-of-line `map` would be
/// compiled without the caller's AVX).
// PHYSICS.md §1.2 (the energy's second derivative); docs/physics-notes.md, "The implicit
// scheme".
#[inline(always)]
fn tet_blocks_in<L: Lane>(
    rest: &RestLanes,
    tan: &TangentLanes,
    definite: bool,
) -> [[[f32; LANES]; 9]; 10] {
    let (f, cof) = (M3::<L>::load(&tan.f), M3::<L>::load(&tan.cof));
    let volume = L::new(rest.volume);
    let mu = L::new(tan.scalars[0]);
    let (mut c, mut s3) = (L::new(tan.scalars[1]), L::new(tan.scalars[2]));
    if definite {
        c = c.max(L::ZERO);
        s3 = s3.max(-(mu / largest_stretch_bound(&f)));
    }
    let (mu, c, s3) = (mu * volume, c * volume, s3 * volume);
    let bt = M3::<L>::load(&rest.dm_inv).transpose();
    let b = [-(bt.c0 + bt.c1 + bt.c2), bt.c0, bt.c1, bt.c2];
    let a = [
        cof.mul_vec(b[0]),
        cof.mul_vec(b[1]),
        cof.mul_vec(b[2]),
        cof.mul_vec(b[3]),
    ];
    let mut out = [[[0.0; LANES]; 9]; 10];
    for (o, &(j, k)) in out.iter_mut().zip(PAIRS.iter()) {
        let ca = a[j] * c;
        let d = b[j].dot(b[k]) * mu;
        let g = f.mul_vec(b[j].cross(b[k])) * s3;
        for (o, e) in o.iter_mut().zip(pair_entries(d, ca, a[k], g)) {
            *o = e.to_array();
        }
    }
    out
}

/// The entries, row-major, of `d I + ca yᵀ − [g]ₓ`: `pair_block` with `d = μ (β_j·β_k)`,
/// `ca = c a_j`, `y = a_k` and `g = s₃ F (β_j × β_k)` (coarse_assembly.rs).
#[inline(always)]
pub(super) fn pair_entries<L: Lane>(d: L, ca: V3<L>, y: V3<L>, g: V3<L>) -> [L; 9] {
    [
        d + ca.x * y.x,
        ca.x * y.y + g.z,
        ca.x * y.z - g.y,
        ca.y * y.x - g.z,
        d + ca.y * y.y,
        ca.y * y.z + g.x,
        ca.z * y.x + g.y,
        ca.z * y.y - g.x,
        d + ca.z * y.z,
    ]
}

/// `σ̂ ≥ σ_max(F)`, at least 1 (tet_tangent.rs `largest_stretch_bound`).
#[inline(always)]
fn largest_stretch_bound<L: Lane>(f: &M3<L>) -> L {
    let c = f.transpose().mul_mat(f);
    let row = |r: fn(&V3<L>) -> L| r(&c.c0).abs() + r(&c.c1).abs() + r(&c.c2).abs();
    let (x, y, z) = (row(|v| v.x), row(|v| v.y), row(|v| v.z));
    x.max(y).max(z).sqrt().max(L::ONE)
}
