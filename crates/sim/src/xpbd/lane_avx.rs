//! Eight lanes in one AVX register (`__m256`), for the projection compiled for AVX2 that
//! [`super::lane_pass`] runs when the CPU has it, so a portable build uses AVX too.
//!
//! Every operation is an AVX intrinsic, `#[inline(always)]`, so that it is compiled into
//! that function. **Only use it where AVX2 is known to be present**: the crate creates an
//! `Avx` only under `is_x86_feature_detected!("avx2")` (the projection and the tests).

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

use super::lane::{LANES, Lane, LaneMath};

/// Eight `f32` in an AVX register.
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub struct Avx(__m256);

impl Avx {
    /// The register (for [`super::lane_nodes`]'s loads and stores).
    #[inline(always)]
    pub(super) fn raw(self) -> __m256 {
        self.0
    }

    /// Eight lanes from a register.
    #[inline(always)]
    pub(super) fn from_raw(v: __m256) -> Avx {
        Avx(v)
    }
}

/// `f` on the register, which needs AVX.
macro_rules! avx {
    ($e:expr) => {
        // SAFETY: an `Avx` exists only where AVX2 was detected (module docs).
        Avx(unsafe { $e })
    };
}

impl Lane for Avx {
    #[inline(always)]
    fn new(v: [f32; LANES]) -> Self {
        avx!(_mm256_loadu_ps(v.as_ptr()))
    }
    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        let mut out = [0.0; LANES];
        // SAFETY: as `avx!`; `out` holds eight f32.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
        out
    }
}

impl LaneMath for Avx {
    // SAFETY: `__m256` is eight `f32`, any bits are valid.
    const ZERO: Self = Avx(unsafe { std::mem::transmute::<[f32; LANES], __m256>([0.0; LANES]) });
    // SAFETY: as above.
    const ONE: Self = Avx(unsafe { std::mem::transmute::<[f32; LANES], __m256>([1.0; LANES]) });
    const ALL: u32 = (1 << LANES) - 1;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        avx!(_mm256_set1_ps(v))
    }
    #[inline(always)]
    fn simd_lt(self, o: Self) -> Self {
        avx!(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0))
    }
    #[inline(always)]
    fn simd_gt(self, o: Self) -> Self {
        avx!(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0))
    }
    #[inline(always)]
    fn simd_ge(self, o: Self) -> Self {
        avx!(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0))
    }
    #[inline(always)]
    fn select(self, t: Self, f: Self) -> Self {
        avx!(_mm256_blendv_ps(f.0, t.0, self.0))
    }
    #[inline(always)]
    fn is_finite(self) -> Self {
        self.abs().simd_lt(Avx::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        avx!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        avx!(_mm256_sqrt_ps(self.0))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        avx!(_mm256_max_ps(self.0, o.0))
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        // SAFETY: as `avx!`.
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
    /// The Cephes `logf` polynomial, as `wide` evaluates it ([`ln_of_parts`]).
    #[inline(always)]
    fn ln(self) -> Self {
        // SAFETY: as `avx!` (AVX2 for the integer shifts).
        let (m, e) = unsafe {
            let bits = _mm256_castps_si256(self.0);
            let exponent = _mm256_sub_epi32(_mm256_srli_epi32::<23>(bits), _mm256_set1_epi32(126));
            let mantissa = _mm256_or_si256(
                _mm256_and_si256(bits, _mm256_set1_epi32(0x807f_ffff_u32 as i32)),
                _mm256_set1_epi32(0x3f00_0000),
            );
            (
                Avx(_mm256_castsi256_ps(mantissa)),
                Avx(_mm256_cvtepi32_ps(exponent)),
            )
        };
        ln_of_parts(m, e)
    }
}

/// `ln x` from `x = m 2^e` with `m` in [½, 1) (the bits' mantissa and exponent): the
/// Cephes `logf` polynomial as `wide` evaluates it: `m` moved to [√½, √2), then
/// `ln x = e ln 2 + ln m` (ln 2 split in two), `ln(1 + f)` of degree 9. The AVX and
/// AVX-512 lanes share it, so their lanes agree bit for bit.
#[inline(always)]
pub(super) fn ln_of_parts<L: LaneMath>(m: L, e: L) -> L {
    let s = L::splat;
    let small = m.simd_lt(s(std::f32::consts::FRAC_1_SQRT_2));
    let e = e - (small & L::ONE);
    let f = m - L::ONE + (small & m);
    let z = f * f;
    let mut y = s(7.037_683_6e-2);
    for c in [
        -1.151_461e-1,
        1.167_699_9e-1,
        -1.242_014_1e-1,
        1.424_932_3e-1,
        -1.666_805_8e-1,
        2.000_071_5e-1,
        -2.499_999_4e-1,
        0.333_333_3,
    ] {
        y = y * f + s(c);
    }
    let y = y * f * z + e * s(-2.121_944_4e-4) - z * s(0.5);
    f + y + e * s(0.693_359_4)
}

impl Add for Avx {
    type Output = Avx;
    #[inline(always)]
    fn add(self, o: Avx) -> Avx {
        avx!(_mm256_add_ps(self.0, o.0))
    }
}

impl Sub for Avx {
    type Output = Avx;
    #[inline(always)]
    fn sub(self, o: Avx) -> Avx {
        avx!(_mm256_sub_ps(self.0, o.0))
    }
}

impl Mul for Avx {
    type Output = Avx;
    #[inline(always)]
    fn mul(self, o: Avx) -> Avx {
        avx!(_mm256_mul_ps(self.0, o.0))
    }
}

impl Div for Avx {
    type Output = Avx;
    #[inline(always)]
    fn div(self, o: Avx) -> Avx {
        avx!(_mm256_div_ps(self.0, o.0))
    }
}

impl Neg for Avx {
    type Output = Avx;
    #[inline(always)]
    fn neg(self) -> Avx {
        avx!(_mm256_xor_ps(_mm256_set1_ps(-0.0), self.0))
    }
}

impl BitAnd for Avx {
    type Output = Avx;
    /// Both masks set (or a value where the mask is set, zero elsewhere).
    #[inline(always)]
    fn bitand(self, o: Avx) -> Avx {
        avx!(_mm256_and_ps(self.0, o.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation against `wide`'s on the same lanes (the portable lane type), where
    /// the CPU has AVX2.
    #[test]
    fn avx_lanes_compute_what_the_portable_lanes_compute() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipping: no AVX2");
            return;
        }
        use wide::f32x8;
        let a = [0.3f32, 1.0, 2.5, 1e-3, 7.0, 0.999, 1.2e4, 0.1];
        let b = [1.0f32, -2.0, 2.5, 0.5, -1e-3, 3.0, 0.25, 0.1];
        let (pa, pb) = (f32x8::new(a), f32x8::new(b));
        let (xa, xb) = (Avx::new(a), Avx::new(b));
        let same = |p: f32x8, x: Avx, what: &str, ulp: u32| {
            for (k, (p, x)) in p.to_array().iter().zip(x.to_array()).enumerate() {
                let d = (p.to_bits() as i64 - x.to_bits() as i64).unsigned_abs();
                assert!(d <= ulp as u64, "{what} lane {k}: {p} vs {x}");
            }
        };
        same(pa + pb, xa + xb, "+", 0);
        same(pa - pb, xa - xb, "-", 0);
        same(pa * pb, xa * xb, "*", 0);
        same(pa / pb, xa / xb, "/", 0);
        same(-pa, -xa, "neg", 0);
        same(LaneMath::abs(pb), LaneMath::abs(xb), "abs", 0);
        same(LaneMath::sqrt(pa), LaneMath::sqrt(xa), "sqrt", 0);
        same(LaneMath::max(pa, pb), LaneMath::max(xa, xb), "max", 0);
        same(LaneMath::ln(pa), LaneMath::ln(xa), "ln", 1);
        let (mp, mx) = (LaneMath::simd_lt(pa, pb), LaneMath::simd_lt(xa, xb));
        same(mp, mx, "<", 0);
        same(LaneMath::simd_gt(pa, pb), LaneMath::simd_gt(xa, xb), ">", 0);
        same(
            LaneMath::simd_ge(pa, pb),
            LaneMath::simd_ge(xa, xb),
            ">=",
            0,
        );
        same(mp & pa, mx & xa, "&", 0);
        same(mp.select(pa, pb), LaneMath::select(mx, xa, xb), "select", 0);
        let inf = [
            f32::INFINITY,
            f32::NAN,
            1.0,
            -1.0,
            0.0,
            f32::MAX,
            -f32::INFINITY,
            3.0,
        ];
        same(
            LaneMath::is_finite(f32x8::new(inf)),
            LaneMath::is_finite(Avx::new(inf)),
            "is_finite",
            0,
        );
    }
}
