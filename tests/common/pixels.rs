//! Pixel checks shared by the image tests of every command that draws: the tissue's and
//! the cut surface's colours, the body's box on screen (its rest bounding box projected
//! with the camera that drew it), CPU/GPU agreement and small golden PNGs under
//! `tests/golden/` (rewritten with `INCISE_BLESS=pictures`), compared whole and by their
//! tissue and cut-surface masks (crates/xr/tests/common/masks.rs, shared with the
//! renderer's tests).

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use incise_xr::{RgbaImage, View};

use super::masks::{GOLDEN_MASKS, mask_failures};
// The colour tests, where the image tests have always found them (not every test binary
// that includes this module uses them).
#[allow(unused_imports)]
pub use super::masks::{is_cut, is_tissue};

/// A pixel rectangle, `x0..x1` × `y0..y1`, inside an image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenBox {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// One past the right column.
    pub x1: u32,
    /// One past the bottom row.
    pub y1: u32,
}

impl ScreenBox {
    /// The pixels of `img` inside the box.
    pub fn pixels<'a>(&self, img: &'a RgbaImage) -> impl Iterator<Item = [u8; 4]> + 'a {
        let b = *self;
        (b.y0..b.y1).flat_map(move |y| (b.x0..b.x1).map(move |x| img.get(x, y)))
    }

    /// Number of pixels in the box.
    pub fn area(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    /// A box of half-size `r` pixels around `p`, clipped to a `w` × `h` image.
    pub fn around(p: Vec2, r: f32, w: u32, h: u32) -> ScreenBox {
        ScreenBox::clipped(p - Vec2::splat(r), p + Vec2::splat(r), w, h)
    }

    fn clipped(lo: Vec2, hi: Vec2, w: u32, h: u32) -> ScreenBox {
        let cx = |v: f32| (v.max(0.0) as u32).min(w);
        let cy = |v: f32| (v.max(0.0) as u32).min(h);
        ScreenBox {
            x0: cx(lo.x.floor()),
            y0: cy(lo.y.floor()),
            x1: cx(hi.x.ceil()),
            y1: cy(hi.y.ceil()),
        }
    }
}

/// The screen box of the axis-aligned box `lo..hi` (its 8 corners projected through
/// `view`) in a `w` × `h` image; panics when a corner is behind the camera.
pub fn projected_box(view: &View, lo: Vec3, hi: Vec3, w: u32, h: u32) -> ScreenBox {
    let size = Vec2::new(w as f32, h as f32);
    let (mut a, mut b) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let p = view
            .project(c, size)
            .unwrap_or_else(|| panic!("corner {c} is behind the camera"));
        (a, b) = (a.min(p), b.max(p));
    }
    ScreenBox::clipped(a, b, w, h)
}

/// The default camera of `incise render` / screenshots for the scene at `scene` (a path
/// from the workspace root), for a `w` × `h` image, and the mesh's rest bounds.
pub fn scene_view(scene: &str, w: u32, h: u32) -> (View, Vec3, Vec3) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let s = incise::scene::load_scene(&path).unwrap();
    let built = incise::scene::build_scene(&s, &path, None).unwrap();
    let mesh = built.solver.mesh();
    let (lo, hi) = mesh.rest_bounds();
    let view = incise::pictures::screenshots::default_camera(mesh).view(w as f32 / h as f32);
    (view, lo, hi)
}

/// Share of the pixels in `b` for which `pred` holds.
pub fn share(img: &RgbaImage, b: ScreenBox, pred: impl Fn([u8; 4]) -> bool) -> f64 {
    b.pixels(img).filter(|p| pred(*p)).count() as f64 / b.area().max(1) as f64
}

/// Number of pixels of the whole image for which `pred` holds.
pub fn count(img: &RgbaImage, pred: impl Fn([u8; 4]) -> bool) -> usize {
    img.pixels
        .chunks_exact(4)
        .filter(|p| pred([p[0], p[1], p[2], p[3]]))
        .count()
}

/// Share of pixels whose channels differ by at most `tol` between `a` and `b`.
pub fn agreeing_share(a: &RgbaImage, b: &RgbaImage, tol: u8) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "image sizes differ"
    );
    let same = a
        .pixels
        .chunks_exact(4)
        .zip(b.pixels.chunks_exact(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).all(|(x, y)| x.abs_diff(*y) <= tol))
        .count();
    same as f64 / (a.width * a.height) as f64
}

/// The CPU and GPU pictures of the same frame agree: at least 98 % of the pixels within
/// 24 levels per channel.
pub fn assert_devices_agree(what: &str, cpu: &RgbaImage, gpu: &RgbaImage) {
    let agree = agreeing_share(cpu, gpu, 24);
    assert!(
        agree >= 0.98,
        "{what}: CPU and GPU pictures agree on only {:.2} % of pixels",
        agree * 100.0
    );
}

/// `tests/golden/NAME.png`.
pub fn golden_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"))
}

/// Compare `img` with its golden image `tests/golden/NAME.png` ([`assert_like_golden`]).
/// `INCISE_BLESS=pictures` (or `all`) writes `img` as the golden instead, after the
/// physics or the renderer changed on purpose (refused under CI).
pub fn assert_golden(name: &str, img: &RgbaImage) {
    if incise_test_gate::bless(incise_test_gate::Bless::Pictures) {
        let path = golden_path(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        img.save_png(&path).unwrap();
        eprintln!("blessed {}", path.display());
        return;
    }
    assert_like_golden(name, "cpu", img);
}

/// The golden image `tests/golden/NAME.png`; panics saying how to write it.
fn load_golden(name: &str) -> RgbaImage {
    let path = golden_path(name);
    RgbaImage::load_png(&path).unwrap_or_else(|e| {
        panic!(
            "no golden image {} ({e}); write it with INCISE_BLESS=pictures",
            path.display()
        )
    })
}

/// Compare `img`, drawn with the solver on `device`, with the golden image
/// `tests/golden/NAME.png`, never rewriting it ([`golden_failures`]). On failure the
/// picture is saved in the temporary folder and every failed check is named.
pub fn assert_like_golden(name: &str, device: &str, img: &RgbaImage) {
    let golden = load_golden(name);
    assert_eq!(
        (img.width, img.height),
        (golden.width, golden.height),
        "{name}: size differs from the golden image"
    );
    let failures = golden_failures(name, &golden, img);
    if !failures.is_empty() {
        let seen = std::env::temp_dir().join(format!("incise-{name}-{device}-actual.png"));
        img.save_png(&seen).unwrap();
        panic!(
            "{} (golden {}, this picture on the {device}: {}); if the change is meant, \
             rewrite the goldens with INCISE_BLESS=pictures",
            failures.join("\n"),
            golden_path(name).display(),
            seen.display()
        );
    }
}

/// How `img` fails its golden, one message a check: the whole picture (at least 98 % of
/// the pixels within 24 levels per channel) and the tissue and the cut surface where the
/// golden has them ([`GOLDEN_MASKS`]: the whole-picture allowance, 2 %, is more than
/// each golden's cut surface, so only the masks see a cut missing, recoloured or moved).
pub fn golden_failures(name: &str, golden: &RgbaImage, img: &RgbaImage) -> Vec<String> {
    let agree = agreeing_share(img, golden, 24);
    let whole = (agree < 0.98).then(|| {
        format!(
            "{name}: only {:.2} % of pixels match the golden",
            agree * 100.0
        )
    });
    let masks = mask_failures(name, golden, img, &GOLDEN_MASKS);
    whole.into_iter().chain(masks).collect()
}
