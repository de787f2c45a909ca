//! Sixteen lanes in one AVX-512 register (`__m512`): two blocks of eight tets projected
//! at once by the function compiled for AVX-512 that [`super::lane_pass`] runs when the
//! CPU has it (issue 35, item 3). Lane by lane the same operations as
//! [`super::lane_avx::Avx`]: IEEE `+ − × ÷ √`, the same `ln` ([`ln_of_parts`]), no fused
//! multiply-add, masks with every bit set or clear; so a tet's bits do not depend on
//! which of the two projected it.
//!
//! Every operation is an AVX-512F intrinsic, `#[inline(always)]`. **Only use it where
//! AVX-512F is known to be present**: the crate creates an `Avx512` only inside functions
//! entered under `is_x86_feature_detected!("avx512f")` (the projection and the tests).

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

use super::lane::LaneMath;
use super::lane_avx::{Avx, ln_of_parts};
use super::lane_slots::LaneBlock;
use super::lanes::{LANES, Lane, M3, V3};
use super::rest_free_lanes::TetLanes;

/// Number of lanes.
const WIDE: usize = 16;

/// Sixteen `f32` in an AVX-512 register.
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub struct Avx512(__m512);

/// `e` on registers, which needs AVX-512F.
macro_rules! avx512 {
    ($e:expr) => {
        // SAFETY: an `Avx512` exists only where AVX-512F was detected (module docs).
        Avx512(unsafe { $e })
    };
}

impl Avx512 {
    /// The register.
    #[inline(always)]
    pub(super) fn raw(self) -> __m512 {
        self.0
    }

    /// Lanes of a register (only where AVX-512F is present: module docs).
    #[inline(always)]
    pub(super) fn from_raw(v: __m512) -> Avx512 {
        Avx512(v)
    }

    /// Lanes 0–7 from `lo`, 8–15 from `hi`.
    #[inline(always)]
    pub(super) fn join(lo: Avx, hi: Avx) -> Avx512 {
        avx512!({
            let lo = _mm512_castpd256_pd512(_mm256_castps_pd(lo.raw()));
            _mm512_castpd_ps(_mm512_insertf64x4::<1>(lo, _mm256_castps_pd(hi.raw())))
        })
    }

    /// Lanes 0–7 and 8–15.
    #[inline(always)]
    pub(super) fn split(self) -> (Avx, Avx) {
        // SAFETY: as `avx512!`.
        unsafe {
            let hi = _mm512_extractf64x4_pd::<1>(_mm512_castps_pd(self.0));
            (
                Avx::from_raw(_mm512_castps512_ps256(self.0)),
                Avx::from_raw(_mm256_castpd_ps(hi)),
            )
        }
    }

    /// The mask register of a mask's set lanes.
    #[inline(always)]
    fn mask(self) -> __mmask16 {
        // SAFETY: as `avx512!`. A set lane has its sign bit set.
        unsafe { _mm512_movepi32_mask_f(self.0) }
    }

    /// A mask with the lanes of `k` set.
    #[inline(always)]
    fn from_mask(k: __mmask16) -> Avx512 {
        avx512!(_mm512_castsi512_ps(_mm512_maskz_mov_epi32(
            k,
            _mm512_set1_epi32(-1)
        )))
    }

    /// The lanes' bits.
    #[inline(always)]
    fn int(self) -> __m512i {
        // SAFETY: as `avx512!`.
        unsafe { _mm512_castps_si512(self.0) }
    }
}

/// The lanes whose sign bit is set, with AVX-512F alone (`vpmovd2m` needs AVX-512DQ).
///
/// # Safety
/// AVX-512F is present.
#[inline(always)]
unsafe fn _mm512_movepi32_mask_f(v: __m512) -> __mmask16 {
    // SAFETY: the caller's contract.
    unsafe { _mm512_cmplt_epi32_mask(_mm512_castps_si512(v), _mm512_setzero_si512()) }
}

impl LaneMath for Avx512 {
    // SAFETY: `__m512` is sixteen `f32`, any bits are valid.
    const ZERO: Self = Avx512(unsafe { std::mem::transmute::<[f32; WIDE], __m512>([0.0; WIDE]) });
    // SAFETY: as above.
    const ONE: Self = Avx512(unsafe { std::mem::transmute::<[f32; WIDE], __m512>([1.0; WIDE]) });
    const ALL: u32 = (1 << WIDE) - 1;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        avx512!(_mm512_set1_ps(v))
    }
    #[inline(always)]
    fn simd_lt(self, o: Self) -> Self {
        // SAFETY: as `avx512!`.
        Avx512::from_mask(unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn simd_gt(self, o: Self) -> Self {
        // SAFETY: as `avx512!`.
        Avx512::from_mask(unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn simd_ge(self, o: Self) -> Self {
        // SAFETY: as `avx512!`.
        Avx512::from_mask(unsafe { _mm512_cmp_ps_mask::<_CMP_GE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn select(self, t: Self, f: Self) -> Self {
        avx512!(_mm512_mask_blend_ps(self.mask(), f.0, t.0))
    }
    #[inline(always)]
    fn is_finite(self) -> Self {
        self.abs().simd_lt(Avx512::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        avx512!(_mm512_castsi512_ps(_mm512_and_si512(
            self.int(),
            _mm512_set1_epi32(i32::MAX)
        )))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        avx512!(_mm512_sqrt_ps(self.0))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        avx512!(_mm512_max_ps(self.0, o.0))
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        self.mask() as u32
    }
    /// As the AVX lanes' `ln` ([`ln_of_parts`]).
    #[inline(always)]
    fn ln(self) -> Self {
        // SAFETY: as `avx512!`.
        let (m, e) = unsafe {
            let bits = _mm512_castps_si512(self.0);
            let exponent = _mm512_sub_epi32(_mm512_srli_epi32::<23>(bits), _mm512_set1_epi32(126));
            let mantissa = _mm512_or_si512(
                _mm512_and_si512(bits, _mm512_set1_epi32(0x807f_ffff_u32 as i32)),
                _mm512_set1_epi32(0x3f00_0000),
            );
            (
                Avx512(_mm512_castsi512_ps(mantissa)),
                Avx512(_mm512_cvtepi32_ps(exponent)),
            )
        };
        ln_of_parts(m, e)
    }
}

impl Add for Avx512 {
    type Output = Avx512;
    #[inline(always)]
    fn add(self, o: Avx512) -> Avx512 {
        avx512!(_mm512_add_ps(self.0, o.0))
    }
}

impl Sub for Avx512 {
    type Output = Avx512;
    #[inline(always)]
    fn sub(self, o: Avx512) -> Avx512 {
        avx512!(_mm512_sub_ps(self.0, o.0))
    }
}

impl Mul for Avx512 {
    type Output = Avx512;
    #[inline(always)]
    fn mul(self, o: Avx512) -> Avx512 {
        avx512!(_mm512_mul_ps(self.0, o.0))
    }
}

impl Div for Avx512 {
    type Output = Avx512;
    #[inline(always)]
    fn div(self, o: Avx512) -> Avx512 {
        avx512!(_mm512_div_ps(self.0, o.0))
    }
}

impl Neg for Avx512 {
    type Output = Avx512;
    #[inline(always)]
    fn neg(self) -> Avx512 {
        avx512!(_mm512_castsi512_ps(_mm512_xor_si512(
            self.int(),
            Avx512::splat(-0.0).int()
        )))
    }
}

impl BitAnd for Avx512 {
    type Output = Avx512;
    /// Both masks set (or a value where the mask is set, zero elsewhere).
    #[inline(always)]
    fn bitand(self, o: Avx512) -> Avx512 {
        avx512!(_mm512_castsi512_ps(_mm512_and_si512(self.int(), o.int())))
    }
}

/// Lanes 0–7 from `lo`, 8–15 from `hi`.
#[inline(always)]
fn join_v3(lo: V3<Avx>, hi: V3<Avx>) -> V3<Avx512> {
    V3 {
        x: Avx512::join(lo.x, hi.x),
        y: Avx512::join(lo.y, hi.y),
        z: Avx512::join(lo.z, hi.z),
    }
}

/// Lanes 0–7 from `lo`, 8–15 from `hi`.
#[inline(always)]
fn join_m3(lo: &M3<Avx>, hi: &M3<Avx>) -> M3<Avx512> {
    M3 {
        c0: join_v3(lo.c0, hi.c0),
        c1: join_v3(lo.c1, hi.c1),
        c2: join_v3(lo.c2, hi.c2),
    }
}

/// Two blocks' tets in sixteen lanes (`lo`'s in 0–7, `hi`'s in 8–15): their terms beside
/// their nodes' displacements `u` and inverse masses `w` (read by
/// [`super::lane_pair_nodes::load_pair`]).
#[inline(always)]
pub(super) fn pair_tets(
    lo: &LaneBlock,
    hi: &LaneBlock,
    (u, w): ([V3<Avx512>; 4], [Avx512; 4]),
) -> TetLanes<Avx512> {
    TetLanes {
        u,
        w,
        dm_inv: join_m3(&M3::load(&lo.dm_inv), &M3::load(&hi.dm_inv)),
        alpha_h: join_arrays(&lo.alpha_h, &hi.alpha_h),
        alpha_d: join_arrays(&lo.alpha_d, &hi.alpha_d),
        live: join_arrays(&lo.live, &hi.live),
    }
}

/// Lanes 0–7 from `lo`, 8–15 from `hi` (no closure: it would be compiled without the
/// caller's AVX-512 and call each intrinsic).
#[inline(always)]
fn join_arrays(lo: &[f32; LANES], hi: &[f32; LANES]) -> Avx512 {
    Avx512::join(Avx::new(*lo), Avx::new(*hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xpbd::lane::Lane;

    /// Every operation against the AVX lanes' on the same values, bit for bit, in both
    /// halves, where the CPU has AVX-512F. Broken on purpose once (`select`'s arms
    /// swapped): fails.
    #[test]
    fn avx512_lanes_compute_what_the_avx_lanes_compute() {
        if !std::arch::is_x86_feature_detected!("avx512f") {
            eprintln!("skipping: no AVX-512F");
            return;
        }
        let a = [0.3f32, 1.0, 2.5, 1e-3, 7.0, 0.999, 1.2e4, 0.1];
        let b = [1.0f32, -2.0, 2.5, 0.5, -1e-3, 3.0, 0.25, 0.1];
        let c = [
            f32::INFINITY,
            f32::NAN,
            0.0,
            -0.0,
            f32::MAX,
            1e-30,
            -f32::INFINITY,
            3.0,
        ];
        let (xa, xb, xc) = (Avx::new(a), Avx::new(b), Avx::new(c));
        let (wa, wb, wc) = (
            Avx512::join(xa, xb),
            Avx512::join(xb, xc),
            Avx512::join(xc, xa),
        );
        let same = |w: Avx512, lo: Avx, hi: Avx, what: &str| {
            let (l, h) = w.split();
            for (got, want) in [(l, lo), (h, hi)] {
                let (g, e) = (got.to_array(), want.to_array());
                for k in 0..8 {
                    assert_eq!(g[k].to_bits(), e[k].to_bits(), "{what} lane {k}");
                }
            }
        };
        same(wa + wb, xa + xb, xb + xc, "+");
        same(wa - wb, xa - xb, xb - xc, "-");
        same(wa * wb, xa * xb, xb * xc, "*");
        same(wa / wb, xa / xb, xb / xc, "/");
        same(-wc, -xc, -xa, "neg");
        same(wc.abs(), xc.abs(), xa.abs(), "abs");
        same(wa.sqrt(), xa.sqrt(), xb.sqrt(), "sqrt");
        same(wa.max(wb), xa.max(xb), xb.max(xc), "max");
        same(wa.ln(), xa.ln(), xb.ln(), "ln");
        same(wa.abs().ln(), xa.abs().ln(), xb.abs().ln(), "ln");
        let (mw, m0, m1) = (wa.simd_lt(wb), xa.simd_lt(xb), xb.simd_lt(xc));
        same(mw, m0, m1, "<");
        same(wa.simd_gt(wb), xa.simd_gt(xb), xb.simd_gt(xc), ">");
        same(wa.simd_ge(wb), xa.simd_ge(xb), xb.simd_ge(xc), ">=");
        same(mw & wa, m0 & xa, m1 & xb, "&");
        same(
            mw.select(wa, wb),
            m0.select(xa, xb),
            m1.select(xb, xc),
            "select",
        );
        same(wc.is_finite(), xc.is_finite(), xa.is_finite(), "is_finite");
        assert_eq!(mw.bits(), m0.bits() | (m1.bits() << 8), "bits");
        assert_eq!(Avx512::splat(1.0).simd_gt(Avx512::ZERO).bits(), Avx512::ALL);
    }
}
