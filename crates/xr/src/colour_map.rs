//! The stress heat map's colour scale on the host (for legends), the same polynomial as
//! `fs_stress` in `shaders/render/tet_faces.wgsl`.

/// Turbo colour map (Mikhailov 2019, polynomial fit): sRGB in [0, 1] for `t` in [0, 1]
/// (clamped).
pub fn turbo(t: f32) -> [f32; 3] {
    let x = t.clamp(0.0, 1.0);
    let v4 = [1.0, x, x * x, x * x * x];
    let v2 = [v4[2] * v4[2], v4[3] * v4[2]];
    let dot4 = |c: [f32; 4]| c.iter().zip(v4).map(|(a, b)| a * b).sum::<f32>();
    let dot2 = |c: [f32; 2]| c[0] * v2[0] + c[1] * v2[1];
    [
        dot4([0.135_721_38, 4.615_392_6, -42.660_32, 132.131_08]) + dot2([-152.942_4, 59.286_38]),
        dot4([0.091_402_61, 2.194_188_4, 4.842_966_6, -14.185_033])
            + dot2([4.277_298_6, 2.829_566]),
        dot4([0.106_673_3, 12.641_946, -60.582_05, 110.362_77]) + dot2([-89.903_11, 27.348_25]),
    ]
    .map(|c| c.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_from_near_black_through_green_to_dark_red() {
        let lo = turbo(0.0);
        assert!(lo[2] > lo[1] && lo.iter().all(|&c| c < 0.2), "{lo:?}");
        let blue = turbo(0.15);
        assert!(
            blue[2] > 0.8 && blue[2] > blue[0] && blue[2] > blue[1],
            "{blue:?}"
        );
        let mid = turbo(0.5);
        assert!(mid[1] > 0.8, "{mid:?}");
        let hi = turbo(1.0);
        assert!(hi[0] > 0.4 && hi[1] < 0.1 && hi[2] < 0.1, "{hi:?}");
        assert_eq!(turbo(-3.0), lo);
        assert_eq!(turbo(7.0), hi);
    }
}
