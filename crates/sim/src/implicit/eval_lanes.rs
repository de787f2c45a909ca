//! The Newton step's tet evaluation eight tets at a time in SIMD lanes: for each tet its
//! nodal forces `V P b_a`, the diagonal blocks of its Hessian, its energy `V Ψ` and its
//! stress tangent, at the current iterate. The same formulas as the scalar evaluation
//! (`tet_evals.rs`, `scalar_eval`, with [`crate::vbd::piola`],
//! [`crate::vbd::energy_density`] and [`super::TetTangent::at`]), which stays the reference
//! (`cpu_kernel: Scalar`) and is tested equal to it up to rounding; built on the XPBD
//! lanes' strain algebra (`crate::xpbd::rest_free_lanes`), in one AVX register per value
//! where the CPU has AVX2 (detected at run time), else in `wide::f32x8`.

use glam::{Mat3, Vec3};

use super::product_lanes::{RestLanes, TangentLanes, corners};
use crate::material::Lame;
use crate::xpbd::lane_nodes::NodeLanes;
use crate::xpbd::lanes::{LANES, Lane, M3};
use crate::xpbd::rest_free_lanes::{StrainLanes, log_volume, log1p_excess, shape_energy};

/// Eight tets' evaluation: nodal forces, the upper triangles of the diagonal blocks
/// (xx, yy, zz, xy, xz, yz) and energies, stored entry by entry across the lanes (zero in
/// lanes without a live tet).
#[derive(Debug, Clone, Copy)]
pub struct EvalLanes {
    forces: [[[f32; LANES]; 3]; 4],
    diag: [[[f32; LANES]; 6]; 4],
    energy: [f32; LANES],
}

impl EvalLanes {
    /// All zero: what a chunk without live tets evaluates to.
    pub const ZERO: EvalLanes = EvalLanes {
        forces: [[[0.0; LANES]; 3]; 4],
        diag: [[[0.0; LANES]; 6]; 4],
        energy: [0.0; LANES],
    };

    /// The force on corner `a` of lane `k`'s tet, N.
    #[inline]
    pub fn force(&self, k: usize, a: usize) -> Vec3 {
        let f = &self.forces[a];
        Vec3::new(f[0][k], f[1][k], f[2][k])
    }

    /// The diagonal Hessian block of corner `a` of lane `k`'s tet, N/m.
    #[inline]
    pub fn diag(&self, k: usize, a: usize) -> Mat3 {
        let d = &self.diag[a];
        let (xx, yy, zz, xy, xz, yz) = (d[0][k], d[1][k], d[2][k], d[3][k], d[4][k], d[5][k]);
        Mat3::from_cols(
            Vec3::new(xx, xy, xz),
            Vec3::new(xy, yy, yz),
            Vec3::new(xz, yz, zz),
        )
    }

    /// The energies of the chunk's tets, J.
    #[inline]
    pub fn energies(&self) -> &[f32; LANES] {
        &self.energy
    }
}

/// Evaluate the chunk `rest` at the displacements `u` (`live`: one flag per tet of the
/// chunk) into `out` and its tangents into `tan` (a tet that is not live keeps a tangent
/// that no product reads).
pub fn evaluate(
    rest: &RestLanes,
    live: &[bool],
    u: &[Vec3],
    lame: Lame,
    out: &mut EvalLanes,
    tan: &mut TangentLanes,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { evaluate_avx2(rest, live, u, lame, out, tan) };
    }
    evaluate_in::<wide::f32x8>(rest, live, u, lame, out, tan);
}

/// The energies alone of the chunk at `u`, into `out`'s energies (its forces and blocks
/// stay as they were); the values [`evaluate`] gives, to the bit.
pub fn energy(rest: &RestLanes, live: &[bool], u: &[Vec3], lame: Lame, out: &mut EvalLanes) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { energy_avx2(rest, live, u, lame, out) };
    }
    energy_in::<wide::f32x8>(rest, live, u, lame, out);
}

/// [`evaluate_in`] with AVX lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn evaluate_avx2(
    rest: &RestLanes,
    live: &[bool],
    u: &[Vec3],
    lame: Lame,
    out: &mut EvalLanes,
    tan: &mut TangentLanes,
) {
    evaluate_in::<crate::xpbd::lane_avx::Avx>(rest, live, u, lame, out, tan);
}

/// [`energy_in`] with AVX lanes, compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
unsafe fn energy_avx2(
    rest: &RestLanes,
    live: &[bool],
    u: &[Vec3],
    lame: Lame,
    out: &mut EvalLanes,
) {
    energy_in::<crate::xpbd::lane_avx::Avx>(rest, live, u, lame, out);
}

/// What the energy and the evaluation share: the strain and `L(J)` of each lane, and the
/// mask of the live lanes.
struct Deformation<L> {
    s: StrainLanes<L>,
    /// `(L, L', J > J_MIN)`.
    volume: (L, L, L),
    excess: L,
    cof: M3<L>,
    live: L,
}

/// The chunk's strains at `u` (PHYSICS.md §1.2: `F = I + Du Dm⁻¹`).
#[inline(always)]
fn deformation<L: NodeLanes>(rest: &RestLanes, live: &[bool], u: &[Vec3]) -> Deformation<L> {
    let mut mask = [0.0f32; LANES];
    for k in (0..rest.count).filter(|&k| live[k]) {
        mask[k] = f32::from_bits(u32::MAX);
    }
    let [d0, d1, d2, d3] = corners::<L>(rest, u);
    let du = M3 {
        c0: d1 - d0,
        c1: d2 - d0,
        c2: d3 - d0,
    };
    let s = StrainLanes::of(du.mul_mat(&M3::load(&rest.dm_inv)));
    let excess = log1p_excess(s.j1);
    let volume = log_volume(&s, excess);
    let cof = s.cof_f();
    Deformation {
        s,
        volume,
        excess,
        cof,
        live: L::new(mask),
    }
}

/// `V Ψ = V (μ/2 ψ̂ + λ/2 L²)` per lane (vbd `energy_density`), 0 where not live.
#[inline(always)]
fn energies<L: Lane>(d: &Deformation<L>, psi: L, volume: L, lame: Lame) -> L {
    let l = d.volume.0;
    let half = L::splat(0.5);
    let density = half * L::splat(lame.mu) * psi + half * L::splat(lame.lambda) * l * l;
    d.live.select(volume * density, L::ZERO)
}

/// The chunk's energies in lanes of type `L`.
#[inline(always)]
fn energy_in<L: NodeLanes>(
    rest: &RestLanes,
    live: &[bool],
    u: &[Vec3],
    lame: Lame,
    out: &mut EvalLanes,
) {
    let d = deformation::<L>(rest, live, u);
    let (psi, _) = shape_energy(&d.s, d.volume, d.excess, &d.cof);
    out.energy = energies(&d, psi, L::new(rest.volume), lame).to_array();
}

/// The chunk's evaluation in lanes of type `L` (loops written out: an out-of-line `map`
/// would be compiled without the caller's AVX).
// PHYSICS.md §1.2 (the rest-free pair's energy); docs/physics-notes.md, "The implicit
// scheme" (the tangent and the diagonal blocks).
#[inline(always)]
fn evaluate_in<L: NodeLanes>(
    rest: &RestLanes,
    live: &[bool],
    u: &[Vec3],
    lame: Lame,
    out: &mut EvalLanes,
    tan: &mut TangentLanes,
) {
    let d = deformation::<L>(rest, live, u);
    let (psi, half) = shape_energy(&d.s, d.volume, d.excess, &d.cof);
    let (l, dl, above) = d.volume;
    let (mu, lambda) = (L::splat(lame.mu), L::splat(lame.lambda));
    let volume = L::new(rest.volume);
    out.energy = energies(&d, psi, volume, lame).to_array();
    // The tangent (tet_tangent.rs `TetTangent::at`).
    let ddl = above.select(-(dl * dl), L::ZERO);
    let pressure = lambda * l - mu;
    let c = lambda * dl * dl + pressure * ddl;
    let s3 = pressure * dl;
    tan.f = (M3::diagonal(L::ONE) + d.s.h).to_arrays();
    tan.cof = d.cof.to_arrays();
    tan.scalars = [mu.to_array(), c.to_array(), s3.to_array()];
    // Forces V P b_a (vbd `piola`) and blocks V [μ |b|² I + c⁺ (cof b)(cof b)ᵀ].
    let p = (half * mu + d.cof * (lambda * l * dl)) * volume;
    let bt = M3::<L>::load(&rest.dm_inv).transpose();
    let b = [-(bt.c0 + bt.c1 + bt.c2), bt.c0, bt.c1, bt.c2];
    let c_plus = c.max(L::ZERO) * volume;
    let zero = L::ZERO;
    for (a, ba) in b.iter().enumerate() {
        let f = p.mul_vec(*ba);
        out.forces[a] = [
            d.live.select(f.x, zero).to_array(),
            d.live.select(f.y, zero).to_array(),
            d.live.select(f.z, zero).to_array(),
        ];
        let g = d.cof.mul_vec(*ba);
        let iso = mu * ba.length_squared() * volume;
        let entry = |v: L| d.live.select(v, zero).to_array();
        out.diag[a] = [
            entry(iso + c_plus * g.x * g.x),
            entry(iso + c_plus * g.y * g.y),
            entry(iso + c_plus * g.z * g.z),
            entry(c_plus * g.x * g.y),
            entry(c_plus * g.x * g.z),
            entry(c_plus * g.y * g.z),
        ];
    }
}
