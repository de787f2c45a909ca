//! The one-page HTML report of an attempt: metrics table, pass/fail per condition, plots
//! of the blade force over time and the cut depth along the plan, and pictures of the cut
//! when an offscreen renderer was available. Self-contained: images are inline PNG data.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};

use super::result::ExerciseResult;
use crate::report::plot::{LineChart, Series, write_line_chart};

/// Pictures of the cut, or why there are none.
pub enum CutImages<'a> {
    /// PNG files: (caption, path).
    Files(Vec<(&'a str, &'a Path)>),
    /// Why no picture was rendered.
    Missing(String),
}

/// Write `force.png` and `depth.png` into `dir`, then `report.html` there with them and
/// `images` inlined; returns the report's path.
pub fn write(dir: &Path, r: &ExerciseResult, images: &CutImages) -> Result<std::path::PathBuf> {
    let m = &r.metrics;
    let force_png = dir.join("force.png");
    write_line_chart(
        &force_png,
        &LineChart {
            title: "Contact force on the blade".into(),
            x_label: "time (s)".into(),
            y_label: "|force| (N)".into(),
            series: vec![
                Series {
                    name: "blade force".into(),
                    points: m.force_series.clone(),
                },
                Series {
                    name: "limit".into(),
                    points: limit_line(&m.force_series, r.thresholds.max_force as f64),
                },
            ],
        },
        900,
        360,
    )?;
    let depth_png = dir.join("depth.png");
    let to_mm = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
        pts.iter().map(|&(s, d)| (s * 1e3, d * 1e3)).collect()
    };
    let target = r.target_depth as f64;
    let tol = r.tolerance.depth as f64;
    write_line_chart(
        &depth_png,
        &LineChart {
            title: "Cut depth along the planned incision".into(),
            x_label: "along the plan (mm)".into(),
            y_label: "depth (mm)".into(),
            series: vec![
                Series {
                    name: "cut".into(),
                    points: to_mm(&m.depth_profile),
                },
                Series {
                    name: "target".into(),
                    points: to_mm(&limit_line(&m.depth_profile, target)),
                },
                Series {
                    name: "deepest allowed".into(),
                    points: to_mm(&limit_line(&m.depth_profile, target + tol)),
                },
            ],
        },
        900,
        360,
    )?;
    let mut html = String::new();
    let verdict = if r.verdict.passed { "PASS" } else { "FAIL" };
    let colour = if r.verdict.passed {
        "#1a7f37"
    } else {
        "#c62828"
    };
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{name}: {verdict}</title>\n\
         <style>body{{font-family:sans-serif;max-width:960px;margin:2em auto;color:#222}}\
         table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #ccc;padding:4px 10px;text-align:left}}\
         .pass{{color:#1a7f37}}.fail{{color:#c62828}}img{{max-width:100%}}</style></head><body>\n\
         <h1>{name} — <span style=\"color:{colour}\">{verdict}</span>, score {score:.0} / 100</h1>\n\
         <p>{desc}</p>\n<p>Stroke <code>{stroke}</code> on scene <code>{scene}</code>, {frames} frames on {device}, scored {time}.</p>\n",
        name = esc(&r.exercise),
        desc = esc(&r.description),
        score = r.verdict.score,
        stroke = esc(&r.stroke_file),
        scene = esc(&r.scene_file),
        frames = r.frames,
        device = esc(&r.device),
        time = r.time,
    );
    html.push_str("<h2>Pass conditions</h2>\n<table><tr><th>condition</th><th>result</th><th>detail</th></tr>\n");
    for c in &r.verdict.checks {
        let (class, word) = if c.passed {
            ("pass", "pass")
        } else {
            ("fail", "FAIL")
        };
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td class=\"{class}\">{word}</td><td>{}</td></tr>",
            c.name,
            esc(&c.detail)
        );
    }
    html.push_str("</table>\n<h2>Metrics</h2>\n<table><tr><th>metric</th><th>value</th><th>score points</th></tr>\n");
    let mm =
        |v: Option<f64>| v.map_or("— (nothing cut)".into(), |x| format!("{:.2} mm", x * 1e3));
    let p = &r.verdict.parts;
    let w = &super::score::WEIGHTS;
    let rows = [
        (
            "completion",
            format!("{:.1} %", m.completion * 100.0),
            Some((p.completion, w.completion)),
        ),
        (
            "mean deviation",
            mm(m.mean_deviation),
            Some((p.deviation, w.deviation)),
        ),
        ("max deviation", mm(m.max_deviation), None),
        (
            "mean depth error",
            mm(m.mean_depth_error),
            Some((p.depth, w.depth)),
        ),
        ("deepest cut", mm(Some(m.max_depth)), None),
        (
            "collateral damage",
            format!(
                "{:.1} mm³ ({:.0} % of the tolerance band's {:.0} mm³)",
                m.collateral_volume * 1e9,
                100.0 * m.collateral_volume / m.band_volume,
                m.band_volume * 1e9
            ),
            Some((p.collateral, w.collateral)),
        ),
        (
            "max contact force",
            format!("{:.2} N", m.max_force),
            Some((p.force, w.force)),
        ),
        ("mean contact force", format!("{:.2} N", m.mean_force), None),
        ("strokes", m.strokes.to_string(), None),
        (
            "duration",
            format!("{:.2} s", m.duration),
            Some((p.time, w.time)),
        ),
        (
            "released tets",
            format!("{} ({:.1} mm³)", m.released_tets, m.released_volume * 1e9),
            None,
        ),
        ("plan length", mm(Some(m.plan_length)), None),
        ("tet edge (resolution)", mm(Some(m.tet_edge)), None),
    ];
    for (name, value, points) in rows {
        let pts = points.map_or(String::new(), |(got, of)| format!("{got:.1} / {of:.0}"));
        let _ = writeln!(
            html,
            "<tr><td>{name}</td><td>{}</td><td>{pts}</td></tr>",
            esc(&value)
        );
    }
    html.push_str("</table>\n<p>Definitions and weights: docs/scoring.md.</p>\n<h2>Plots</h2>\n");
    html.push_str(&img_tag(&force_png, "contact force over time")?);
    html.push_str(&img_tag(&depth_png, "cut depth along the plan")?);
    html.push_str("<h2>The cut</h2>\n");
    match images {
        CutImages::Files(files) => {
            for (caption, path) in files {
                let _ = write!(html, "<p>{}</p>", esc(caption));
                html.push_str(&img_tag(path, caption)?);
            }
        }
        CutImages::Missing(why) => {
            let _ = writeln!(html, "<p><em>No pictures: {}.</em></p>", esc(why));
        }
    }
    html.push_str("</body></html>\n");
    let path = dir.join("report.html");
    incise_sim::io::write_atomic(&path, html.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// A horizontal line at `y` over the x range of `points`.
fn limit_line(points: &[(f64, f64)], y: f64) -> Vec<(f64, f64)> {
    match (points.first(), points.last()) {
        (Some(a), Some(b)) => vec![(a.0, y), (b.0, y)],
        _ => Vec::new(),
    }
}

/// An `<img>` with the PNG at `path` inlined as base64 data.
fn img_tag(path: &Path, alt: &str) -> Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(format!(
        "<img alt=\"{}\" src=\"data:image/png;base64,{}\">\n",
        esc(alt),
        base64(&bytes)
    ))
}

/// Standard base64 (RFC 4648, with padding).
fn base64(bytes: &[u8]) -> String {
    const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(TABLE[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Text escaped for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
        assert_eq!(esc("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
    }
}
