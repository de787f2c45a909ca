//! The arithmetic of one tet projection, counted: a [`Lane`] type that tallies every
//! floating-point operation the batched projection ([`super::rest_free_lanes`]) performs,
//! so that `incise bench realtime` can divide a sweep's time into the work it did
//! (GFLOP/s against the machine's peak, issue 35) from a count, not a guess.
//!
//! Counted as one flop per lane: `+ − × ÷ √`. Not counted: negation, `abs`, `max`,
//! comparisons, masks and selects (bit operations). `ln` counts [`LN_FLOPS`], the
//! arithmetic of the polynomial both lane types evaluate (`lane_avx.rs`, `wide`'s `ln`).
//! A branch of the scalar reference is evaluated for a block of eight tets when one of
//! them takes it (`rest_free_lanes::Taken`), so the count is that of the common block:
//! eight tets strained a little (|J − 1| < 0.1, J above J_MIN, both constraints on), the
//! organ's tets between cuts; a block whose tets take different branches does more.

use std::cell::Cell;
use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

use glam::{Mat3, Vec3};

use super::lane::{LANES, Lane, LaneMath};
use super::lanes::{M3, V3};
use super::rest_free_lanes::{TetLanes, project_rest_free_lanes};

/// Flops of one `ln`: `lane_avx.rs`'s exponent and mantissa fix-up (3), `f²` (1), the
/// degree-9 Horner loop (16), the tail (6) and the sum with `e ln 2` (3).
pub const LN_FLOPS: u64 = 29;

/// Flops per node per substep outside the projection: the prediction `v += h g`,
/// `u += h v` (12) and the velocity update `v = (u − u_prev)/h · keep` (9)
/// (PHYSICS.md §1.2, small-steps loop).
pub const NODE_FLOPS_PER_SUBSTEP: u64 = 21;

thread_local! {
    static FLOPS: Cell<u64> = const { Cell::new(0) };
}

/// Count `n` flops.
fn tally(n: u64) {
    FLOPS.with(|c| c.set(c.get() + n));
}

/// Eight `f32` that count the arithmetic done on them (one lane's worth: a lane type's
/// operation is one flop per tet).
#[derive(Debug, Clone, Copy)]
struct Counted([f32; LANES]);

impl Counted {
    /// `f` per lane.
    fn map(self, f: impl Fn(f32) -> f32) -> Counted {
        Counted(self.0.map(f))
    }

    /// `f` per pair of lanes.
    fn zip(self, o: Counted, f: impl Fn(f32, f32) -> f32) -> Counted {
        Counted(std::array::from_fn(|k| f(self.0[k], o.0[k])))
    }

    /// A mask lane: all bits set where `b`.
    fn mask(b: bool) -> f32 {
        f32::from_bits(if b { u32::MAX } else { 0 })
    }
}

macro_rules! counted_op {
    ($trait:ident, $fn:ident, $op:tt, $flops:expr) => {
        impl $trait for Counted {
            type Output = Counted;
            fn $fn(self, o: Counted) -> Counted {
                tally($flops);
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}

counted_op!(Add, add, +, 1);
counted_op!(Sub, sub, -, 1);
counted_op!(Mul, mul, *, 1);
counted_op!(Div, div, /, 1);

impl Neg for Counted {
    type Output = Counted;
    fn neg(self) -> Counted {
        self.map(|a| -a)
    }
}

impl BitAnd for Counted {
    type Output = Counted;
    fn bitand(self, o: Counted) -> Counted {
        self.zip(o, |a, b| f32::from_bits(a.to_bits() & b.to_bits()))
    }
}

impl Lane for Counted {
    fn new(v: [f32; LANES]) -> Self {
        Counted(v)
    }
    fn to_array(self) -> [f32; LANES] {
        self.0
    }
}

impl LaneMath for Counted {
    const ZERO: Self = Counted([0.0; LANES]);
    const ONE: Self = Counted([1.0; LANES]);
    const ALL: u32 = (1 << LANES) - 1;
    fn splat(v: f32) -> Self {
        Counted([v; LANES])
    }
    fn simd_lt(self, o: Self) -> Self {
        self.zip(o, |a, b| Counted::mask(a < b))
    }
    fn simd_gt(self, o: Self) -> Self {
        self.zip(o, |a, b| Counted::mask(a > b))
    }
    fn simd_ge(self, o: Self) -> Self {
        self.zip(o, |a, b| Counted::mask(a >= b))
    }
    fn select(self, t: Self, f: Self) -> Self {
        Counted(std::array::from_fn(|k| {
            if self.0[k].to_bits() != 0 {
                t.0[k]
            } else {
                f.0[k]
            }
        }))
    }
    fn is_finite(self) -> Self {
        self.map(|a| Counted::mask(a.is_finite()))
    }
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    fn sqrt(self) -> Self {
        tally(1);
        self.map(f32::sqrt)
    }
    fn max(self, o: Self) -> Self {
        self.zip(o, f32::max)
    }
    fn ln(self) -> Self {
        tally(LN_FLOPS);
        self.map(f32::ln)
    }
    fn bits(self) -> u32 {
        (0..LANES).fold(0, |b, k| b | (((self.0[k].to_bits() >> 31) & 1) << k))
    }
}

/// Flops of one rest-free coupled tet projection (the lane kernels' work per tet),
/// counted by running the projection once on eight tets stretched and sheared by up to
/// 8 % (the common block of the module docs).
pub fn projection_flops() -> u64 {
    let dm_inv = Mat3::from_diagonal(Vec3::splat(100.0));
    let u: [[Vec3; LANES]; 4] = std::array::from_fn(|j| {
        std::array::from_fn(|k| Vec3::new(1e-4 * (j * k) as f32, 5e-5 * j as f32, 0.0))
    });
    let mut lanes = TetLanes::<Counted> {
        u: u.map(|v| V3::gather(&v)),
        w: [Counted::splat(1e3); 4],
        dm_inv: M3::gather(&[dm_inv; LANES]),
        alpha_h: Counted::splat(1e-3),
        alpha_d: Counted::splat(1e-2),
        live: Counted::splat(Counted::mask(true)),
    };
    FLOPS.with(|c| c.set(0));
    project_rest_free_lanes(&mut lanes);
    FLOPS.with(Cell::get)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The count is what the projection does: about five hundred and fifty flops (547 when
    /// written), the same every call, and it moves when the projection's arithmetic
    /// changes (broken on purpose once: `Mul` not tallied -> the count left the range).
    #[test]
    fn a_projection_counts_a_few_hundred_flops_every_time() {
        let n = projection_flops();
        assert!(
            (500..=600).contains(&n),
            "{n} flops per projection (547 counted)"
        );
        assert_eq!(projection_flops(), n);
    }

    /// The counting lanes compute what the reference lanes compute.
    #[test]
    fn counted_lanes_compute_what_wide_lanes_compute() {
        let a = Counted::new([0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        let w = wide::f32x8::new(a.0);
        let c = ((a * a + a) / (a - Counted::splat(0.25))).sqrt().ln();
        let r = ((w * w + w) / (w - wide::f32x8::splat(0.25))).sqrt().ln();
        for (x, y) in c.0.iter().zip(r.to_array()) {
            assert!((x - y).abs() < 1e-5, "{x} vs {y}");
        }
    }
}
