//! Interpolation between pose keys: non-uniform Catmull–Rom for positions (Hermite
//! segments with tangents from the key times) and shortest-arc slerp for rotations, in
//! f64.

use glam::{DQuat, DVec3, Quat, Vec3};

/// Tangent (velocity, m/s) at key `i` of positions `p` at times `t`.
///
/// Interior keys: the time-weighted three-point difference
/// `m_i = (h₁·d₀ + h₀·d₁) / (h₀ + h₁)` with `h₀ = t_i − t_{i−1}`, `h₁ = t_{i+1} − t_i`,
/// `d₀`, `d₁` the chord velocities either side — the Barry–Goldman tangent of the
/// Catmull–Rom spline with the key times as knots (exact for quadratic motion). End keys:
/// the one-sided chord velocity (the end key duplicated).
pub(crate) fn tangent(t: &[f64], p: &[Vec3], i: usize) -> DVec3 {
    let n = p.len();
    let chord = |a: usize| (p[a + 1].as_dvec3() - p[a].as_dvec3()) / (t[a + 1] - t[a]);
    if i == 0 {
        chord(0)
    } else if i == n - 1 {
        chord(n - 2)
    } else {
        let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
        (chord(i - 1) * h1 + chord(i) * h0) / (h0 + h1)
    }
}

/// Cubic Hermite position on segment `[i, i+1]` at time `time` (inside the segment).
pub(crate) fn hermite(t: &[f64], p: &[Vec3], i: usize, time: f64) -> DVec3 {
    let h = t[i + 1] - t[i];
    let s = ((time - t[i]) / h).clamp(0.0, 1.0);
    let (s2, s3) = (s * s, s * s * s);
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    p[i].as_dvec3() * h00
        + tangent(t, p, i) * (h10 * h)
        + p[i + 1].as_dvec3() * h01
        + tangent(t, p, i + 1) * (h11 * h)
}

/// Spherical linear interpolation from `a` to `b` by `s ∈ [0, 1]` along the shorter arc;
/// the result is normalised.
pub(crate) fn slerp(a: Quat, b: Quat, s: f64) -> Quat {
    let a = a.as_dquat().normalize();
    let mut b = b.as_dquat().normalize();
    let mut dot = a.dot(b);
    if dot < 0.0 {
        b = -b;
        dot = -dot;
    }
    let q = if dot > 1.0 - 1e-12 {
        // Nearly the same rotation: normalised lerp is exact to rounding here.
        a.lerp(b, s)
    } else {
        let theta = dot.clamp(-1.0, 1.0).acos();
        let sin = theta.sin();
        let wa = ((1.0 - s) * theta).sin() / sin;
        let wb = (s * theta).sin() / sin;
        DQuat::from_vec4(glam::DVec4::from(a) * wa + glam::DVec4::from(b) * wb)
    };
    q.normalize().as_quat().normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_motion_is_reproduced_exactly() {
        // x(t) = t² on non-uniform keys: the interior tangent is exact (2t).
        let t = [0.0, 0.5, 2.0, 2.5];
        let p: Vec<Vec3> = t
            .iter()
            .map(|&t| Vec3::new((t * t) as f32, 0.0, 0.0))
            .collect();
        assert!((tangent(&t, &p, 1).x - 1.0).abs() < 1e-6);
        assert!((tangent(&t, &p, 2).x - 4.0).abs() < 1e-6);
        // Between two interior tangents, Hermite reproduces the parabola.
        let x = hermite(&t, &p, 1, 1.25).x;
        assert!((x - 1.5625).abs() < 1e-6, "{x}");
    }

    #[test]
    fn slerp_takes_the_short_way_and_stays_unit() {
        let a = Quat::from_rotation_z(0.1);
        let b = -Quat::from_rotation_z(0.3); // same rotation as +, far hemisphere
        let m = slerp(a, b, 0.5);
        assert!((m.length() - 1.0).abs() < 1e-6);
        let expect = Quat::from_rotation_z(0.2);
        assert!(m.dot(expect).abs() > 1.0 - 1e-6);
        assert!(slerp(a, a, 0.3).dot(a) > 1.0 - 1e-7);
    }
}
