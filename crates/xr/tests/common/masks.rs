//! Golden comparisons that see what a picture shows, not only how many of its pixels agree:
//! the tissue's skin and the cut surface, each as the mask of the pixels of its colour,
//! compared with the same mask of the golden picture by size (the pixel counts), by
//! place (the pixels of either mask with none of the other's nearby) and by centre (the
//! mean position of its pixels). A missing cut, a cut drawn in the skin's colour or a cut
//! moved a few tet widths fails here, though it covers less than the whole-picture
//! comparison's allowance. Used by the renderer's tests and, through `#[path]`, by the
//! app's (tests/common/pixels.rs).
#![allow(dead_code)]

use incise_xr::RgbaImage;

/// The tissue's skin (pink: red well above green and blue); the stress heat map and the
/// cut surface are not skin.
pub fn is_tissue(p: [u8; 4]) -> bool {
    let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
    r > 90 && r - g > 25 && r - b > 10
}

/// The cut surface: the organ's inside, a darker saturated red (the skin has far more
/// green and blue).
pub fn is_cut(p: [u8; 4]) -> bool {
    let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
    r > 60 && r > 2 * g && r > 2 * b
}

/// The pixels of a picture whose colour passes a test.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mask {
    width: u32,
    height: u32,
    on: Vec<bool>,
}

impl Mask {
    /// The pixels of `img` for which `pred` holds.
    pub fn of(img: &RgbaImage, pred: impl Fn([u8; 4]) -> bool) -> Mask {
        let on = img
            .pixels
            .chunks_exact(4)
            .map(|p| pred([p[0], p[1], p[2], p[3]]))
            .collect();
        Mask {
            width: img.width,
            height: img.height,
            on,
        }
    }

    /// Number of pixels in the mask.
    pub fn count(&self) -> usize {
        self.on.iter().filter(|&&b| b).count()
    }

    /// The mask grown by `r` pixels every way (each pixel becomes a (2r+1)² square).
    pub fn grown(&self, r: u32) -> Mask {
        let (w, h) = (self.width as usize, self.height as usize);
        // Along the rows (w pixels a step of 1 apart), then down the columns (h pixels w
        // apart).
        let rows = self.grown_along(r as usize, (w, 1), (h, w));
        rows.grown_along(r as usize, (h, w), (w, 1))
    }

    /// The mask grown by `r` pixels along lines of `len` pixels `step` apart in memory;
    /// there are `count` lines, their first pixels `gap` apart.
    fn grown_along(
        &self,
        r: usize,
        (len, step): (usize, usize),
        (count, gap): (usize, usize),
    ) -> Mask {
        let mut on = vec![false; self.on.len()];
        for start in (0..count).map(|l| l * gap) {
            let at = |i: usize| start + i * step;
            for i in (0..len).filter(|&i| self.on[at(i)]) {
                for j in i.saturating_sub(r)..(i + r + 1).min(len) {
                    on[at(j)] = true;
                }
            }
        }
        Mask { on, ..*self }
    }

    /// The mean position of the mask's pixels (x, y), or `None` when it has none.
    pub fn centre(&self) -> Option<(f64, f64)> {
        let w = self.width as usize;
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
        for i in (0..self.on.len()).filter(|&i| self.on[i]) {
            (sx, sy, n) = (sx + (i % w) as f64, sy + (i / w) as f64, n + 1);
        }
        (n > 0).then(|| (sx / n as f64, sy / n as f64))
    }

    /// Number of this mask's pixels outside `other`.
    pub fn outside(&self, other: &Mask) -> usize {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "mask sizes differ"
        );
        let out = |(a, b): (&bool, &bool)| *a && !*b;
        self.on.iter().zip(&other.on).filter(|p| out(*p)).count()
    }
}

/// How closely one mask of a picture must match the golden's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaskTolerance {
    /// Largest difference of the pixel counts, as a share of the golden's count.
    pub count: f64,
    /// Pixels that may differ or stray whatever the counts (tiny or empty masks).
    pub slack: usize,
    /// How near (pixels, either axis) a pixel of the other mask must be for a match.
    pub reach: u32,
    /// Largest share of either mask's pixels with no pixel of the other within reach.
    pub stray: f64,
    /// Largest distance, pixels, between the two masks' centres (when both have more
    /// than `slack` pixels).
    pub shift: f64,
}

impl MaskTolerance {
    /// The count difference allowed for a golden mask of `golden` pixels.
    fn count_allowed(&self, golden: usize) -> usize {
        ((self.count * golden as f64) as usize).max(self.slack)
    }

    /// The unmatched pixels allowed for a mask of `n` pixels.
    fn stray_allowed(&self, n: usize) -> usize {
        ((self.stray * n as f64) as usize).max(self.slack)
    }
}

/// How one mask of a picture compares with the golden's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaskMatch {
    /// The golden's pixels.
    pub golden: usize,
    /// The picture's pixels.
    pub actual: usize,
    /// The golden's pixels with none of the picture's within reach.
    pub missed: usize,
    /// The picture's pixels with none of the golden's within reach.
    pub strayed: usize,
    /// The distance, pixels, between the masks' centres (`None`: a mask is empty).
    pub moved: Option<f64>,
}

impl MaskMatch {
    /// Compare `actual` with `golden`, a pixel matching when the other mask has one
    /// within `reach` pixels.
    pub fn of(golden: &Mask, actual: &Mask, reach: u32) -> MaskMatch {
        MaskMatch {
            golden: golden.count(),
            actual: actual.count(),
            missed: golden.outside(&actual.grown(reach)),
            strayed: actual.outside(&golden.grown(reach)),
            moved: distance(golden.centre(), actual.centre()),
        }
    }

    /// Why the match fails `tol` (in words, the figures included), or `None`.
    pub fn failure(&self, tol: &MaskTolerance) -> Option<String> {
        let why: Vec<String> = [
            self.count_failure(tol),
            self.place_failure(tol),
            self.shift_failure(tol),
        ]
        .into_iter()
        .flatten()
        .collect();
        (!why.is_empty()).then(|| why.join("; "))
    }

    /// The counts differ by more than `tol` allows.
    fn count_failure(&self, tol: &MaskTolerance) -> Option<String> {
        let (g, a) = (self.golden, self.actual);
        let allowed = tol.count_allowed(g);
        (g.abs_diff(a) > allowed)
            .then(|| format!("{a} pixels against the golden's {g} (±{allowed})"))
    }

    /// Too many pixels of either mask have none of the other's within reach.
    fn place_failure(&self, tol: &MaskTolerance) -> Option<String> {
        let (g, a) = (self.golden, self.actual);
        let (missed, strayed) = (tol.stray_allowed(g), tol.stray_allowed(a));
        (self.missed > missed || self.strayed > strayed).then(|| {
            format!(
                "{} of the golden's {g} pixels have none of this picture's within {r} px \
                 (at most {missed} may), {} of this picture's {a} none of the golden's (at \
                 most {strayed} may)",
                self.missed,
                self.strayed,
                r = tol.reach
            )
        })
    }

    /// The mask's centre moved further than `tol` allows (masks above the slack only).
    fn shift_failure(&self, tol: &MaskTolerance) -> Option<String> {
        let big = self.golden.min(self.actual) > tol.slack;
        let moved = self.moved.filter(|&d| big && d > tol.shift)?;
        Some(format!(
            "its centre is {moved:.2} px from the golden's (at most {} px may be)",
            tol.shift
        ))
    }
}

/// The distance between two points, when both exist.
fn distance(a: Option<(f64, f64)>, b: Option<(f64, f64)>) -> Option<f64> {
    let ((ax, ay), (bx, by)) = (a?, b?);
    Some((ax - bx).hypot(ay - by))
}

/// One mask's check: its name in messages, its pixels' colour test, its tolerance.
#[derive(Clone, Copy)]
pub struct MaskCheck {
    /// What the mask shows, in words ("the cut surface").
    pub what: &'static str,
    /// Whether a pixel belongs to the mask.
    pub pred: fn([u8; 4]) -> bool,
    /// How closely it must match the golden's.
    pub tol: MaskTolerance,
}

impl MaskCheck {
    /// How `img`'s mask compares with `golden`'s.
    pub fn compare(&self, golden: &RgbaImage, img: &RgbaImage) -> MaskMatch {
        let mask = |i| Mask::of(i, self.pred);
        MaskMatch::of(&mask(golden), &mask(img), self.tol.reach)
    }

    /// Why `img` fails this check against `golden` (`name:` and the mask first), or `None`.
    pub fn failure(&self, name: &str, golden: &RgbaImage, img: &RgbaImage) -> Option<String> {
        let m = self.compare(golden, img);
        m.failure(&self.tol)
            .map(|why| format!("{name}: {}: {why}", self.what))
    }
}

/// The failures of each of `checks` by `img` against `golden`, one message each.
pub fn mask_failures(
    name: &str,
    golden: &RgbaImage,
    img: &RgbaImage,
    checks: &[MaskCheck],
) -> Vec<String> {
    checks
        .iter()
        .filter_map(|c| c.failure(name, golden, img))
        .collect()
}

// The tolerances, from lavapipe (Mesa llvmpipe), comparing the goldens (blessed a few
// commits ago) with today's pictures: three runs gave identical pictures, and the GPU
// solver's pictures have the same masks as the CPU's (render and xr eye differ from the
// CPU's in one pixel by one level, the exercise's not at all). Every golden agreed with:
// - tissue: counts within 0.14 % (render 9155 -> 9168, xr eye 3015 -> 3016, exercise
//   32120 -> 32127, rest intestine 8253 -> 8254, torn bar 4530 equal), no pixel without
//   one of the other mask within 1 px (within 0 px up to 18, 0.2 %), centres within 0.05 px;
// - cut surface: counts within 4.3 % (render 136 -> 137, xr eye 188 -> 196, exercise
//   1813 -> 1814, torn bar 1195 equal, the intestine's 85 dark-red shading pixels -> 84),
//   at most 2 of 196 pixels (1 %) without a partner within 1 px (within 0 px 13, 6.6 %),
//   centres within 0.6 px (xr eye).
// (The xr eye's cut mask holds a one-pixel row along the slab's lower front edge, 73 of
// its 188 pixels, whose green is just under half its red: is_cut's edge.)
// Broken on purpose (stroke moved 5 mm in the scene, the stroke file and the headset
// script; the inside drawn in the skin's material or not at all), the cut surface fails:
// not drawn or drawn in the skin's colour, 0–73 pixels against 136–1813; moved 5 mm
// across the incision, 34–66 % of the golden's pixels without a partner and the centre
// 2.4–11.5 px away; moved 5 mm along it, 7–15 % without one in the xr eye and the
// exercise (under the 20 % allowed) but the centre 3.3 px (xr eye), 7.3 px (render) and
// 17.6 px (exercise) away. In the xr eye moved along, only the centre sees it: the whole
// picture still agrees on more than 98 % of its pixels.

/// The tissue's skin: its pixel count within 5 % (at least 25 pixels) of the golden's, at
/// most 5 % of either mask's pixels (at least 25) more than 1 px from the other's, and its
/// centre within 2 px of the golden's.
pub const TISSUE: MaskCheck = MaskCheck {
    what: "the tissue",
    pred: is_tissue,
    tol: MaskTolerance {
        count: 0.05,
        slack: 25,
        reach: 1,
        stray: 0.05,
        shift: 2.0,
    },
};

/// The cut surface: its pixel count within 20 % (at least 10 pixels) of the golden's, at
/// most 20 % of either mask's pixels (at least 10) more than 1 px from the other's, and its
/// centre within 2 px of the golden's (a mask of 10 pixels or fewer has no centre check:
/// a golden without a cut allows 10 stray pixels).
pub const CUT_SURFACE: MaskCheck = MaskCheck {
    what: "the cut surface",
    pred: is_cut,
    tol: MaskTolerance {
        count: 0.2,
        slack: 10,
        reach: 1,
        stray: 0.2,
        shift: 2.0,
    },
};

/// The masks a golden comparison checks besides the whole picture.
pub const GOLDEN_MASKS: [MaskCheck; 2] = [TISSUE, CUT_SURFACE];
