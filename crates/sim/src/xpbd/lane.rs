//! What a lane type of the batched tet projection provides: `f32` lanes (one tet each)
//! with arithmetic, masks (all bits set or clear, as comparisons return) and the few
//! functions the rest-free pair needs ([`LaneMath`], whatever the width), and for eight
//! lanes their loads and stores ([`Lane`]). Eight-lane types: `wide::f32x8`, whose
//! instructions are fixed when the crate is compiled (two SSE registers in the portable
//! build), and [`super::lane_avx::Avx`], one AVX register, used only inside the functions
//! compiled for AVX2 that [`super::lane_pass`] picks at run time; sixteen lanes:
//! [`super::lane_avx512::Avx512`], one AVX-512 register, two blocks at once.

use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

use wide::f32x8;

/// Number of tets projected together.
pub const LANES: usize = 8;

/// The arithmetic of `f32` lanes of any width.
pub trait LaneMath:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + BitAnd<Output = Self>
{
    /// 0.0 in every lane.
    const ZERO: Self;
    /// 1.0 in every lane.
    const ONE: Self;
    /// [`LaneMath::bits`] of a mask with every lane set.
    const ALL: u32;
    /// `v` in every lane.
    fn splat(v: f32) -> Self;
    /// Mask of the lanes where `self < o`.
    fn simd_lt(self, o: Self) -> Self;
    /// Mask of the lanes where `self > o`.
    fn simd_gt(self, o: Self) -> Self;
    /// Mask of the lanes where `self >= o`.
    fn simd_ge(self, o: Self) -> Self;
    /// With `self` a mask: `t` in its set lanes, `f` in the others.
    fn select(self, t: Self, f: Self) -> Self;
    /// Mask of the finite lanes.
    fn is_finite(self) -> Self;
    /// `|x|` per lane.
    fn abs(self) -> Self;
    /// `√x` per lane.
    fn sqrt(self) -> Self;
    /// The larger per lane.
    fn max(self, o: Self) -> Self;
    /// Natural logarithm per lane (finite `x > 0`).
    fn ln(self) -> Self;
    /// With `self` a mask: the lanes set, one bit each (lane `k` is bit `k`).
    fn bits(self) -> u32;
}

/// Eight `f32` lanes, loaded from and stored to arrays.
pub trait Lane: LaneMath {
    /// Lane `k` is `v[k]`.
    fn new(v: [f32; LANES]) -> Self;
    /// The lanes.
    fn to_array(self) -> [f32; LANES];
}

impl Lane for f32x8 {
    #[inline(always)]
    fn new(v: [f32; LANES]) -> Self {
        f32x8::new(v)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        f32x8::to_array(self)
    }
}

impl LaneMath for f32x8 {
    const ZERO: Self = f32x8::ZERO;
    const ONE: Self = f32x8::ONE;
    const ALL: u32 = (1 << LANES) - 1;
    #[inline(always)]
    fn splat(v: f32) -> Self {
        f32x8::splat(v)
    }
    #[inline(always)]
    fn simd_lt(self, o: Self) -> Self {
        f32x8::simd_lt(self, o)
    }
    #[inline(always)]
    fn simd_gt(self, o: Self) -> Self {
        f32x8::simd_gt(self, o)
    }
    #[inline(always)]
    fn simd_ge(self, o: Self) -> Self {
        f32x8::simd_ge(self, o)
    }
    #[inline(always)]
    fn select(self, t: Self, f: Self) -> Self {
        wide::Select::select(self, t, f)
    }
    #[inline(always)]
    fn is_finite(self) -> Self {
        f32x8::is_finite(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32x8::abs(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32x8::sqrt(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        f32x8::max(self, o)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f32x8::ln(self)
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        f32x8::to_bitmask(self)
    }
}
