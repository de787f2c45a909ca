//! The result card: an attempt's verdict as one RGBA image — exercise, PASS or FAIL,
//! score, every pass condition (failed ones in red) and where the attempt stands in the
//! history. The preview shows it in its "Result" window; the headset on a panel quad.
//! Drawn with plotters' bitmap backend and the embedded font (no GPU, no system fonts).

use anyhow::{Result, anyhow};
use incise_xr::RgbaImage;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::attempt::ExerciseResult;
use super::history::HistoryEntry;

/// Size of the card, pixels (16:9, legible on a headset panel about 40 cm wide).
pub const CARD_SIZE: (u32, u32) = (960, 540);

/// Colour of a pass (banner, marks).
pub const PASS_COLOUR: RGBColor = RGBColor(26, 127, 55);

/// Colour of a fail (banner, failed conditions).
pub const FAIL_COLOUR: RGBColor = RGBColor(198, 40, 40);

/// Banner with PASS or FAIL: (left, top, right, bottom), pixels.
pub const BANNER: (i32, i32, i32, i32) = (32, 70, 272, 140);

const BACKGROUND: RGBColor = RGBColor(250, 250, 247);
const INK: RGBColor = RGBColor(34, 34, 34);
const MUTED: RGBColor = RGBColor(110, 110, 110);
const TRACK: RGBColor = RGBColor(220, 220, 215);

/// Where an attempt stands among the attempts at its exercise in the history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Standing {
    /// How many attempts at the exercise the history holds (this one included).
    pub attempts: usize,
    /// The best score among them.
    pub best: f64,
}

impl Standing {
    /// The standing of the latest attempt at `exercise` in `history` (`None` when the
    /// history has no attempt at it).
    pub fn in_history(history: &[HistoryEntry], exercise: &str) -> Option<Standing> {
        let scores: Vec<f64> = history
            .iter()
            .filter(|e| e.exercise == exercise)
            .map(|e| e.score)
            .collect();
        (!scores.is_empty()).then(|| Standing {
            attempts: scores.len(),
            best: scores
                .iter()
                .copied()
                .filter(|s| s.is_finite())
                .fold(f64::NAN, f64::max),
        })
    }
}

/// Draw the card of `result` ([`CARD_SIZE`], opaque sRGB RGBA8), with its `standing` in
/// the history when known. Non-finite numbers are drawn as they print ("NaN").
pub fn render_card(result: &ExerciseResult, standing: Option<Standing>) -> Result<RgbaImage> {
    crate::report::plot::register_fonts();
    let (w, h) = CARD_SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    draw(&mut rgb, result, standing).map_err(|e| anyhow!("drawing the result card: {e}"))?;
    let pixels = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    Ok(RgbaImage {
        width: w,
        height: h,
        pixels,
    })
}

/// Draw into an RGB8 buffer of [`CARD_SIZE`].
fn draw(
    rgb: &mut [u8],
    r: &ExerciseResult,
    standing: Option<Standing>,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::with_buffer(rgb, CARD_SIZE).into_drawing_area();
    root.fill(&BACKGROUND)?;
    let text = |size: u32, colour: RGBColor| ("sans-serif", size).into_font().color(&colour);
    root.draw(&Text::new(
        r.exercise.clone(),
        (BANNER.0, 20),
        text(32, INK),
    ))?;
    let passed = r.verdict.passed;
    let verdict_colour = if passed { PASS_COLOUR } else { FAIL_COLOUR };
    let (l, t, rt, b) = BANNER;
    root.draw(&Rectangle::new([(l, t), (rt, b)], verdict_colour.filled()))?;
    root.draw(&Text::new(
        if passed { "PASS" } else { "FAIL" },
        ((l + rt) / 2, (t + b) / 2),
        text(48, WHITE).pos(Pos::new(HPos::Center, VPos::Center)),
    ))?;
    // Score and a bar with the pass mark.
    let score = r.verdict.score;
    let x0 = rt + 32;
    root.draw(&Text::new(
        format!("score {score:.0} / 100"),
        (x0, t - 2),
        text(34, INK),
    ))?;
    let (bar_l, bar_r, bar_t, bar_b) = (x0, w_i32() - 32, b - 24, b - 8);
    root.draw(&Rectangle::new(
        [(bar_l, bar_t), (bar_r, bar_b)],
        TRACK.filled(),
    ))?;
    let fraction = if score.is_finite() {
        (score / 100.0).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let fill = bar_l + ((bar_r - bar_l) as f64 * fraction).round() as i32;
    if fill > bar_l {
        root.draw(&Rectangle::new(
            [(bar_l, bar_t), (fill, bar_b)],
            verdict_colour.filled(),
        ))?;
    }
    let mark = bar_l
        + ((bar_r - bar_l) as f64 * (r.thresholds.score as f64 / 100.0).clamp(0.0, 1.0)).round()
            as i32;
    root.draw(&Rectangle::new(
        [(mark - 1, bar_t - 6), (mark + 1, bar_b + 6)],
        INK.filled(),
    ))?;
    // The pass conditions.
    let row_h = 32;
    let mut y = b + 22;
    for c in &r.verdict.checks {
        let colour = if c.passed { INK } else { FAIL_COLOUR };
        let dot = if c.passed { PASS_COLOUR } else { FAIL_COLOUR };
        root.draw(&Circle::new((l + 8, y + 9), 7, dot.filled()))?;
        root.draw(&Text::new(c.name, (l + 26, y), text(20, colour)))?;
        root.draw(&Text::new(c.detail.clone(), (l + 210, y), text(19, colour)))?;
        y += row_h;
    }
    let mut footer = match standing {
        Some(s) => format!("attempt {} · best {:.0}", s.attempts, s.best),
        None => "not in the history".to_string(),
    };
    footer.push_str(&format!(" · {} · {}", r.time, r.device));
    root.draw(&Text::new(footer, (l, h_i32() - 36), text(17, MUTED)))?;
    root.present()?;
    Ok(())
}

fn w_i32() -> i32 {
    CARD_SIZE.0 as i32
}

fn h_i32() -> i32 {
    CARD_SIZE.1 as i32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exercise::{Check, Exercise, Metrics, judge};

    fn exercise() -> Exercise {
        ron::from_str(
            "(name: \"slab_depth\", scene: \"s.ron\", plan: [(0,0,0), (0.03,0,0)], depth: 0.003, \
             tolerance: (lateral: 0.003, depth: 0.0025), time_limit: 4.0, pass: (completion: 0.9, \
             mean_deviation: 0.002, max_deviation: 0.004, depth_error: 0.0025, collateral: 1e-7, \
             max_force: 3.0, score: 70))",
        )
        .unwrap()
    }

    fn metrics(deviation: f64) -> Metrics {
        Metrics {
            plan_length: 0.03,
            tet_edge: 0.0025,
            released_tets: 120,
            trace_faces: 40,
            mean_deviation: Some(deviation),
            max_deviation: Some(2.0 * deviation),
            completion: 0.97,
            mean_depth_error: Some(0.0008),
            max_depth: 0.004,
            collateral_volume: 2e-8,
            released_volume: 3e-7,
            cut_faces: 0,
            cut_area: 0.0,
            band_volume: 0.03 * 0.006 * 0.0055,
            max_force: 1.2,
            mean_force: 0.6,
            strokes: 1,
            duration: 1.4,
            depth_profile: vec![],
            force_series: vec![],
        }
    }

    fn result(m: Metrics) -> ExerciseResult {
        let e = exercise();
        ExerciseResult {
            method: crate::scene::Method::Xpbd,
            exercise: e.name.clone(),
            exercise_file: "e.ron".into(),
            description: String::new(),
            scene_file: "s.ron".into(),
            stroke_file: "k.ron".into(),
            device: "cpu".into(),
            time: "2026-01-02T03:04:05Z".into(),
            frames: 100,
            plan: vec![],
            target_depth: e.depth,
            tolerance: e.tolerance,
            time_limit: e.time_limit,
            thresholds: e.pass,
            verdict: judge(&e, &m),
            metrics: m,
        }
    }

    /// Mean colour of the banner's inside.
    fn banner_colour(img: &RgbaImage) -> [f64; 3] {
        let (l, t, r, b) = BANNER;
        let mut sum = [0.0; 3];
        let mut n = 0.0;
        // Left and right strips of the banner, clear of the word.
        for y in (t + 4)..(b - 4) {
            for x in ((l + 3)..(l + 20)).chain((r - 20)..(r - 3)) {
                let p = img.get(x as u32, y as u32);
                (0..3).for_each(|c| sum[c] += p[c] as f64);
                n += 1.0;
            }
        }
        sum.map(|s| s / n)
    }

    /// Share of the card's pixels that are (near) `colour`.
    fn share(img: &RgbaImage, colour: RGBColor) -> f64 {
        let near = img
            .pixels
            .chunks_exact(4)
            .filter(|p| {
                (p[0] as i32 - colour.0 as i32).abs() < 30
                    && (p[1] as i32 - colour.1 as i32).abs() < 30
                    && (p[2] as i32 - colour.2 as i32).abs() < 30
            })
            .count();
        near as f64 / (img.pixels.len() / 4) as f64
    }

    #[test]
    fn pass_and_fail_cards_differ_where_the_verdict_is() {
        let pass = result(metrics(0.0008));
        let fail = result(metrics(0.0045));
        assert!(pass.verdict.passed && !fail.verdict.passed);
        let standing = Some(Standing {
            attempts: 3,
            best: 87.0,
        });
        let a = render_card(&pass, standing).unwrap();
        let b = render_card(&fail, standing).unwrap();
        assert_eq!((a.width, a.height), CARD_SIZE);
        assert_eq!(a.pixels.len(), (CARD_SIZE.0 * CARD_SIZE.1 * 4) as usize);
        assert!(a.pixels.chunks_exact(4).all(|p| p[3] == 255));
        let [r, g, _] = banner_colour(&a);
        assert!(
            g > r + 60.0,
            "PASS banner is not green: {:?}",
            banner_colour(&a)
        );
        let [r, g, _] = banner_colour(&b);
        assert!(
            r > g + 100.0,
            "FAIL banner is not red: {:?}",
            banner_colour(&b)
        );
        // Text was drawn (not only the banner), and the failed conditions in red: the
        // FAIL card has more red than its banner alone.
        let ink = share(&a, INK);
        assert!(ink > 0.005, "hardly any text: {ink}");
        let banner = ((BANNER.2 - BANNER.0) * (BANNER.3 - BANNER.1)) as f64
            / (CARD_SIZE.0 * CARD_SIZE.1) as f64;
        let red = share(&b, FAIL_COLOUR);
        assert!(
            red > banner * 0.8 + 0.002,
            "red share {red}, banner {banner}"
        );
        assert!(share(&a, FAIL_COLOUR) < 0.002, "red on a PASS card");
    }

    #[test]
    fn nan_metrics_draw_without_panicking() {
        let mut m = metrics(f64::NAN);
        m.completion = f64::NAN;
        m.max_force = f64::INFINITY;
        let mut r = result(m);
        r.verdict.score = f64::NAN;
        r.verdict.checks.push(Check {
            name: "extra",
            passed: false,
            detail: "NaN everywhere".into(),
        });
        let img = render_card(&r, None).unwrap();
        assert_eq!((img.width, img.height), CARD_SIZE);
    }

    #[test]
    fn standing_counts_attempts_at_the_same_exercise() {
        let entry = |exercise: &str, score: f64| HistoryEntry {
            time: String::new(),
            exercise: exercise.into(),
            stroke: String::new(),
            score,
            passed: false,
            completion: 0.0,
            mean_deviation: None,
            mean_depth_error: None,
            collateral_volume: 0.0,
            max_force: 0.0,
            strokes: 0,
            duration: 0.0,
            result: String::new(),
        };
        let h = [
            entry("a", 50.0),
            entry("b", 99.0),
            entry("a", 87.0),
            entry("a", 60.0),
        ];
        assert_eq!(
            Standing::in_history(&h, "a"),
            Some(Standing {
                attempts: 3,
                best: 87.0
            })
        );
        assert_eq!(Standing::in_history(&h, "c"), None);
    }
}
