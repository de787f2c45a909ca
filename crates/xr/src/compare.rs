//! Perceptual image comparison for golden-image tests: per-pixel CIE76 colour difference
//! (ΔE in CIELAB), forgiving one-pixel shifts (the smallest ΔE over the reference's 3×3
//! neighbourhood counts), so rasterisers that differ in edge coverage pass while changed
//! shading, geometry or colours fail. A diff image shows where the pixels differ.

use crate::image_io::RgbaImage;

/// How different two images may be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// ΔE above which a pixel counts as different (≈2.3 is just noticeable; 10 is clear).
    pub pixel_delta_e: f32,
    /// Largest fraction of different pixels that still passes.
    pub max_different_fraction: f32,
    /// Largest mean ΔE over all pixels that still passes.
    pub max_mean_delta_e: f32,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance {
            pixel_delta_e: 10.0,
            max_different_fraction: 0.01,
            max_mean_delta_e: 1.5,
        }
    }
}

/// The outcome of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Mean shift-tolerant ΔE over all pixels.
    pub mean_delta_e: f32,
    /// Fraction of pixels above the per-pixel tolerance.
    pub different_fraction: f32,
    /// Largest shift-tolerant ΔE.
    pub max_delta_e: f32,
    /// Whether the images pass the tolerance.
    pub passed: bool,
    /// Grey copy of the reference with differing pixels in red (brighter = larger ΔE).
    pub diff: RgbaImage,
}

impl std::fmt::Display for Comparison {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "mean ΔE {:.2}, {:.2} % of pixels differ, max ΔE {:.1}",
            self.mean_delta_e,
            self.different_fraction * 100.0,
            self.max_delta_e
        )
    }
}

/// Why two images cannot be compared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("image sizes differ: {actual:?} vs reference {reference:?}")]
pub struct SizeMismatch {
    /// Size of the image under test.
    pub actual: (u32, u32),
    /// Size of the reference.
    pub reference: (u32, u32),
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// CIELAB (D65) of an sRGB pixel.
fn lab(p: [u8; 4]) -> [f32; 3] {
    let [r, g, b] = [p[0], p[1], p[2]].map(srgb_to_linear);
    let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
    let f = |t: f32| {
        if t > 0.008856 {
            t.cbrt()
        } else {
            7.787 * t + 16.0 / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

fn delta_e(a: [f32; 3], b: [f32; 3]) -> f32 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Compare `actual` with `reference` under `tol`.
pub fn compare(
    actual: &RgbaImage,
    reference: &RgbaImage,
    tol: Tolerance,
) -> Result<Comparison, SizeMismatch> {
    if (actual.width, actual.height) != (reference.width, reference.height) {
        return Err(SizeMismatch {
            actual: (actual.width, actual.height),
            reference: (reference.width, reference.height),
        });
    }
    let (w, h) = (actual.width, actual.height);
    let to_lab = |img: &RgbaImage| -> Vec<[f32; 3]> {
        img.pixels
            .chunks_exact(4)
            .map(|p| lab([p[0], p[1], p[2], p[3]]))
            .collect()
    };
    let (la, lr) = (to_lab(actual), to_lab(reference));
    let mut diff = RgbaImage::filled(w, h, [0, 0, 0, 255]);
    let (mut sum, mut max, mut different) = (0.0f64, 0.0f32, 0usize);
    for y in 0..h {
        for x in 0..w {
            let a = la[(y * w + x) as usize];
            // Smallest difference to the reference's neighbourhood, and the reverse (so a
            // thin feature missing from either image is still caught).
            let near = |img: &[[f32; 3]], p: [f32; 3]| {
                let mut best = f32::INFINITY;
                for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                    for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                        best = best.min(delta_e(p, img[(ny * w + nx) as usize]));
                    }
                }
                best
            };
            let r = lr[(y * w + x) as usize];
            let d = near(&lr, a).max(near(&la, r));
            sum += d as f64;
            max = max.max(d);
            let grey = (r[0] * 2.55 * 0.4) as u8;
            if d > tol.pixel_delta_e {
                different += 1;
                let v = (128.0 + d * 4.0).min(255.0) as u8;
                diff.set(x, y, [v, 0, 0, 255]);
            } else {
                diff.set(x, y, [grey, grey, grey, 255]);
            }
        }
    }
    let n = (w * h).max(1) as f32;
    let mean = (sum / n as f64) as f32;
    let fraction = different as f32 / n;
    Ok(Comparison {
        mean_delta_e: mean,
        different_fraction: fraction,
        max_delta_e: max,
        passed: fraction <= tol.max_different_fraction && mean <= tol.max_mean_delta_e,
        diff,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32) -> RgbaImage {
        let mut img = RgbaImage::filled(w, h, [0, 0, 0, 255]);
        for y in 0..h {
            for x in 0..w {
                img.set(x, y, [(x * 4) as u8, (y * 4) as u8, 120, 255]);
            }
        }
        img
    }

    #[test]
    fn identical_and_slightly_noisy_images_pass() {
        let a = gradient(40, 30);
        let c = compare(&a, &a, Tolerance::default()).unwrap();
        assert!(
            c.passed && c.mean_delta_e == 0.0 && c.max_delta_e == 0.0,
            "{c}"
        );
        let mut b = a.clone();
        for p in b.pixels.chunks_exact_mut(4) {
            p[0] = p[0].saturating_add(1);
        }
        let c = compare(&b, &a, Tolerance::default()).unwrap();
        assert!(c.passed, "{c}");
    }

    #[test]
    fn a_one_pixel_shift_passes_but_a_new_shape_fails_with_a_diff() {
        let mut a = RgbaImage::filled(40, 30, [30, 30, 30, 255]);
        let mut shifted = a.clone();
        for y in 10..20 {
            for x in 10..20 {
                a.set(x, y, [220, 40, 40, 255]);
                shifted.set(x + 1, y, [220, 40, 40, 255]);
            }
        }
        assert!(compare(&shifted, &a, Tolerance::default()).unwrap().passed);
        let mut changed = a.clone();
        for y in 0..8 {
            for x in 25..38 {
                changed.set(x, y, [40, 200, 40, 255]);
            }
        }
        let c = compare(&changed, &a, Tolerance::default()).unwrap();
        assert!(!c.passed, "{c}");
        assert!(
            (c.different_fraction - 8.0 * 13.0 / 1200.0).abs() < 0.02,
            "{c}"
        );
        // The diff marks the changed block red and leaves the rest grey.
        assert!(c.diff.get(30, 4)[0] >= 128 && c.diff.get(30, 4)[1] == 0);
        let g = c.diff.get(2, 25);
        assert!(g[0] == g[1] && g[1] == g[2]);
        // A missing thin feature fails too (both directions are checked).
        let mut line = RgbaImage::filled(40, 30, [30, 30, 30, 255]);
        for x in 0..40 {
            line.set(x, 15, [255, 255, 255, 255]);
        }
        let blank = RgbaImage::filled(40, 30, [30, 30, 30, 255]);
        let c = compare(
            &blank,
            &line,
            Tolerance {
                max_different_fraction: 0.01,
                ..Tolerance::default()
            },
        )
        .unwrap();
        assert!(!c.passed, "{c}");
        assert!(
            compare(
                &blank,
                &RgbaImage::filled(4, 4, [0; 4]),
                Tolerance::default()
            )
            .is_err()
        );
    }
}
