//! Issue 20: offscreen pictures of every method. `incise render` of a Nakao scene draws
//! the plate and, after the stroke, the wound along the blade's path (background showing
//! through the opened cut where the plate at rest is whole); `incise run
//! --screenshot-every` of a rheology scene draws the heat map of its edge strain, uniform
//! at rest and hot under the indenter once it presses.

mod common;

use std::path::Path;

use common::pixels::{ScreenBox, is_tissue, projected_box, share};
use common::{incise, temp_dir, text};
use glam::{Vec2, Vec3};
use incise::pictures::screenshots::default_camera;
use incise::pictures::tet_drawing::TetDrawing;
use incise::scene::load_scene;
use incise::sim_body::{OpenOptions, open};
use incise_xr::{RgbaImage, View};

const NAKAO: &str = "config/plate_cut_nakao.ron";
const SIZE: (u32, u32) = (480, 270);

/// The camera `incise render` frames `scene`'s body with, at rest.
fn camera_of(scene: &str) -> View {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let opts = OpenOptions {
        quiet: true,
        ..OpenOptions::default()
    };
    let (body, _) = open(&load_scene(&path).unwrap(), &path, &opts).unwrap();
    let drawing = TetDrawing::new(body.tet_view()).unwrap();
    default_camera(&drawing.render.mesh).view(SIZE.0 as f32 / SIZE.1 as f32)
}

/// Screen position of world point `p`.
fn project(view: &View, p: Vec3) -> Vec2 {
    let c = view.proj * view.view * p.extend(1.0);
    let ndc = c.truncate() / c.w;
    Vec2::new(
        (ndc.x + 1.0) * 0.5 * SIZE.0 as f32,
        (1.0 - ndc.y) * 0.5 * SIZE.1 as f32,
    )
}

/// Pixels within `r` of the segment `a`–`b` (its middle 80 %) that are not tissue, and
/// the band's pixel count.
fn gaps_along(img: &RgbaImage, a: Vec2, b: Vec2, r: f32) -> (usize, usize) {
    let (a, b) = (a + (b - a) * 0.1, a + (b - a) * 0.9);
    let (mut gap, mut all) = (0, 0);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            if p.distance(a + (b - a) * t) <= r {
                all += 1;
                gap += !is_tissue(img.get(x, y)) as usize;
            }
        }
    }
    (gap, all)
}

/// `incise render SCENE --frame N OUT --size WxH [--overlay stress]`; the picture.
fn render(dir: &Path, scene: &str, frame: u32, extra: &[&str]) -> RgbaImage {
    let out = dir.join(format!("frame-{frame}.png"));
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let frame = frame.to_string();
    let mut args = vec![
        "render",
        scene,
        "--frame",
        &frame,
        out.to_str().unwrap(),
        "--size",
        &size,
    ];
    args.extend_from_slice(extra);
    let o = incise(&args);
    assert!(o.status.success(), "render: {}", text(&o.stderr));
    RgbaImage::load_png(&out).unwrap()
}

#[test]
fn render_draws_the_nakao_plate_and_its_opened_wound() {
    let dir = temp_dir("pictures-nakao");
    let view = camera_of(NAKAO);
    let top = 0.002;
    let body: ScreenBox = projected_box(
        &view,
        Vec3::new(-0.06, -0.06, top),
        Vec3::new(0.06, 0.06, top),
        SIZE.0,
        SIZE.1,
    );
    // The stroke's edge (heel to tip at x = −0.07, y = −4.8 mm) travels (0.14, 10.3 mm).
    let (a, b) = (
        project(&view, Vec3::new(-0.07, -0.0048, top)),
        project(&view, Vec3::new(0.07, 0.0055, top)),
    );
    let rest = render(&dir, NAKAO, 0, &[]);
    let cut = render(&dir, NAKAO, 160, &[]);
    for (what, img) in [("at rest", &rest), ("after the stroke", &cut)] {
        let tissue = share(img, body, is_tissue);
        assert!(tissue > 0.6, "{what}: {:.0} % tissue", tissue * 100.0);
    }
    let (before, band) = gaps_along(&rest, a, b, 4.0);
    let (after, _) = gaps_along(&cut, a, b, 4.0);
    eprintln!("gaps along the cut: {before} at rest, {after} after, of {band}");
    assert!(
        before * 50 <= band,
        "gaps in the uncut plate: {before} of {band}"
    );
    assert!(
        after >= 40 && after >= 10 * before.max(1),
        "no wound: {after} of {band}"
    );
}

/// Pixels of the heat map's upper half (yellow to red).
fn hot(img: &RgbaImage) -> usize {
    img.pixels
        .chunks_exact(4)
        .filter(|p| p[0] > 200 && p[2] < 110)
        .count()
}

#[test]
fn run_screenshots_draw_the_rheology_strain_heat_map() {
    let dir = temp_dir("pictures-rheology");
    let out = dir.join("run");
    let o = incise(&[
        "run",
        "config/organ_layers.ron",
        "--frames",
        "60",
        "--screenshot-every",
        "60",
        "--screenshot-size",
        &format!("{}x{}", SIZE.0, SIZE.1),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "run: {}", text(&o.stderr));
    let rest = RgbaImage::load_png(&out.join("frame_00000.png")).unwrap();
    let pressed = RgbaImage::load_png(&out.join("frame_00060.png")).unwrap();
    let (cold, warm) = (hot(&rest), hot(&pressed));
    eprintln!("hot pixels: {cold} at rest, {warm} pressed");
    assert_eq!(cold, 0, "a heat map at rest with hot pixels");
    assert!(
        warm as f64 > 0.005 * (SIZE.0 * SIZE.1) as f64,
        "the pressed body shows {warm} hot pixels"
    );
}
