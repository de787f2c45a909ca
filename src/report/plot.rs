//! PNG figures for experiments: line charts of named (x, y) series, and panels of line
//! segments drawn to scale (mesh side views). Pure Rust: plotters' bitmap backend into a
//! buffer, saved by incise-xr's PNG writer; text through `ab_glyph` with DejaVu Sans
//! embedded (`assets/fonts/`).

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

/// The embedded font (Bitstream Vera licence, see `assets/fonts/README.md`).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Line colours, in series order (repeats after eight).
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Why a figure could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// Drawing or encoding the PNG failed.
    #[error("{path}: {message}")]
    Draw {
        /// The file being written.
        path: String,
        /// What the backend reported.
        message: String,
    },
    /// Nothing to draw, or a coordinate is not finite.
    #[error("{path}: {message}")]
    Data {
        /// The file being written.
        path: String,
        /// What is wrong with the data.
        message: String,
    },
}

/// A named curve of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// A line chart: one or more series on shared axes.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Caption above the plot.
    pub title: String,
    /// Horizontal axis label.
    pub x_label: String,
    /// Vertical axis label.
    pub y_label: String,
    /// The curves.
    pub series: Vec<Series>,
}

/// A set of line segments drawn in one colour (e.g. a mesh's edges in one state).
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentLayer {
    /// Legend text.
    pub name: String,
    /// Segments as ((x0, y0), (x1, y1)).
    pub segments: Vec<[(f64, f64); 2]>,
    /// Index into the palette.
    pub colour: usize,
    /// Faint (thin, translucent) instead of solid.
    pub faint: bool,
}

/// One panel of a segment figure.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentPanel {
    /// Caption of the panel.
    pub title: String,
    /// Layers, drawn in order.
    pub layers: Vec<SegmentLayer>,
}

/// Register the embedded font for plotters' "sans-serif" family (once per process).
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType file checked into the repository.
        if register_font("sans-serif", FontStyle::Normal, FONT).is_err() {
            panic!("embedded font assets/fonts/DejaVuSans.ttf is not a valid TrueType font");
        }
    });
}

/// Write an RGB8 drawing as a PNG, atomically (a killed process leaves the old file or
/// none, never half a PNG).
fn save_rgb(path: &Path, rgb: &[u8], (width, height): (u32, u32)) -> Result<(), PlotError> {
    let image = incise_xr::RgbaImage {
        width,
        height,
        pixels: rgb
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
    };
    image
        .save_png(path)
        .map_err(|e| draw_err(path)(e.to_string()))
}

fn draw_err(path: &Path) -> impl Fn(String) -> PlotError + '_ {
    move |message| PlotError::Draw {
        path: path.display().to_string(),
        message,
    }
}

/// Padded (min, max) of `values`, or an error when empty or not finite.
fn range(path: &Path, values: impl Iterator<Item = f64>) -> Result<(f64, f64), PlotError> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut any = false;
    for v in values {
        if !v.is_finite() {
            return Err(PlotError::Data {
                path: path.display().to_string(),
                message: format!("non-finite coordinate {v}"),
            });
        }
        (lo, hi, any) = (lo.min(v), hi.max(v), true);
    }
    if !any {
        return Err(PlotError::Data {
            path: path.display().to_string(),
            message: "no points to draw".into(),
        });
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-12)
    };
    Ok((lo - pad, hi + pad))
}

/// Write `chart` as a `width` × `height` PNG at `path`.
pub fn write_line_chart(
    path: &Path,
    chart: &LineChart,
    width: u32,
    height: u32,
) -> Result<(), PlotError> {
    register_fonts();
    let points = || chart.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = range(path, points().map(|p| p.0))?;
    let (y0, y1) = range(path, points().map(|p| p.1))?;
    let err = draw_err(path);
    let mut rgb = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        let mut ctx = ChartBuilder::on(&root)
            .caption(&chart.title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(e.to_string()))?;
        ctx.configure_mesh()
            .x_desc(&chart.x_label)
            .y_desc(&chart.y_label)
            .label_style(("sans-serif", 15))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(|e| err(e.to_string()))?;
        for (i, s) in chart.series.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            ctx.draw_series(LineSeries::new(
                s.points.iter().copied(),
                colour.stroke_width(2),
            ))
            .map_err(|e| err(e.to_string()))?
            .label(&s.name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        }
        ctx.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| err(e.to_string()))?;
        root.present().map_err(|e| err(e.to_string()))?;
    }
    save_rgb(path, &rgb, (width, height))
}

/// Write `panels` as a grid of `columns` panels, each `panel_width` × `panel_height`
/// pixels, all with the same axis ranges and equal scale on both axes.
pub fn write_segment_panels(
    path: &Path,
    panels: &[SegmentPanel],
    columns: usize,
    panel_width: u32,
    panel_height: u32,
    axis_labels: (&str, &str),
) -> Result<(), PlotError> {
    register_fonts();
    let columns = columns.clamp(1, panels.len().max(1));
    let rows = panels.len().div_ceil(columns).max(1);
    let ends = || {
        panels
            .iter()
            .flat_map(|p| p.layers.iter())
            .flat_map(|l| l.segments.iter())
            .flat_map(|s| s.iter())
    };
    let (mut x0, mut x1) = range(path, ends().map(|p| p.0))?;
    let (mut y0, mut y1) = range(path, ends().map(|p| p.1))?;
    // Equal scale: widen the narrower range to the plot area's aspect (labels excluded).
    let (plot_w, plot_h) = (panel_width as f64 - 80.0, panel_height as f64 - 90.0);
    let scale = ((x1 - x0) / plot_w).max((y1 - y0) / plot_h);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    (x0, x1) = (cx - 0.5 * scale * plot_w, cx + 0.5 * scale * plot_w);
    (y0, y1) = (cy - 0.5 * scale * plot_h, cy + 0.5 * scale * plot_h);
    let err = draw_err(path);
    let size = (panel_width * columns as u32, panel_height * rows as u32);
    let mut rgb = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        for (area, panel) in root.split_evenly((rows, columns)).iter().zip(panels) {
            let mut ctx = ChartBuilder::on(area)
                .caption(&panel.title, ("sans-serif", 18))
                .margin(8)
                .x_label_area_size(35)
                .y_label_area_size(55)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| err(e.to_string()))?;
            ctx.configure_mesh()
                .x_desc(axis_labels.0)
                .y_desc(axis_labels.1)
                .label_style(("sans-serif", 12))
                .x_labels(5)
                .y_labels(5)
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(|e| err(e.to_string()))?;
            for layer in &panel.layers {
                let colour = PALETTE[layer.colour % PALETTE.len()];
                let style = if layer.faint {
                    colour.mix(0.35).stroke_width(1)
                } else {
                    colour.stroke_width(2)
                };
                ctx.draw_series(
                    layer
                        .segments
                        .iter()
                        .map(|s| PathElement::new(vec![s[0], s[1]], style)),
                )
                .map_err(|e| err(e.to_string()))?
                .label(&layer.name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
            ctx.configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 12))
                .position(SeriesLabelPosition::LowerRight)
                .draw()
                .map_err(|e| err(e.to_string()))?;
        }
        root.present().map_err(|e| err(e.to_string()))?;
    }
    save_rgb(path, &rgb, size)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("incise-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    /// Decode a PNG's size from its IHDR chunk.
    fn png_size(bytes: &[u8]) -> (u32, u32) {
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
        let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
        (be(16), be(20))
    }

    #[test]
    fn line_chart_writes_a_png_of_the_asked_size() {
        let path = tmp("chart.png");
        let chart = LineChart {
            title: "Indentation depth".into(),
            x_label: "time (s)".into(),
            y_label: "depth (mm)".into(),
            series: vec![
                Series {
                    name: "a".into(),
                    points: (0..50)
                        .map(|i| (i as f64 * 0.1, (i as f64 * 0.2).sin()))
                        .collect(),
                },
                Series {
                    name: "b".into(),
                    points: vec![(0.0, 0.0), (5.0, 1.0)],
                },
            ],
        };
        write_line_chart(&path, &chart, 640, 400).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(png_size(&bytes), (640, 400));
    }

    #[test]
    fn segment_panels_tile_and_bad_data_is_an_error() {
        let path = tmp("panels.png");
        let panel = |t: &str| SegmentPanel {
            title: t.into(),
            layers: vec![SegmentLayer {
                name: "edges".into(),
                segments: vec![[(0.0, 0.0), (1.0, 0.5)], [(1.0, 0.5), (0.0, 0.5)]],
                colour: 0,
                faint: false,
            }],
        };
        let panels = [panel("one"), panel("two"), panel("three")];
        write_segment_panels(&path, &panels, 2, 300, 200, ("x", "z")).unwrap();
        assert_eq!(png_size(&std::fs::read(&path).unwrap()), (600, 400));
        let nan = SegmentPanel {
            title: "bad".into(),
            layers: vec![SegmentLayer {
                name: "nan".into(),
                segments: vec![[(0.0, f64::NAN), (1.0, 0.0)]],
                colour: 0,
                faint: true,
            }],
        };
        let e = write_segment_panels(&path, &[nan], 1, 300, 200, ("x", "z")).unwrap_err();
        assert!(e.to_string().contains("non-finite"), "{e}");
    }
}
