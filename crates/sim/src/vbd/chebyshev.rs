//! Chebyshev semi-iterative acceleration of the VBD iterations (Chen et al. 2024, §3.8,
//! after Wang 2015): `x⁽ⁿ⁾ = ω_n (x̄⁽ⁿ⁾ − x⁽ⁿ⁻²⁾) + x⁽ⁿ⁻²⁾`.

/// `ω_n` for iteration `n` (1-based) from `ω_{n−1}`: `ω_1 = 1`, `ω_2 = 2/(2 − ρ²)`,
/// `ω_n = 4/(4 − ρ² ω_{n−1})`.
#[inline]
pub fn chebyshev_omega(n: u32, rho: f32, prev: f32) -> f32 {
    match n {
        0 | 1 => 1.0,
        2 => 2.0 / (2.0 - rho * rho),
        _ => 4.0 / (4.0 - rho * rho * prev),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn omega_rises_to_its_limit() {
        let rho = 0.9f32;
        let mut w = 1.0;
        for n in 1..50 {
            w = chebyshev_omega(n, rho, w);
        }
        // Fixed point of ω = 4/(4 − ρ²ω): 2(1 − sqrt(1 − ρ²))/ρ².
        let limit = 2.0 * (1.0 - (1.0 - rho * rho).sqrt()) / (rho * rho);
        assert!((w - limit).abs() < 1e-5, "{w} vs {limit}");
    }
}
