//! Issue 18: image tests of the commands that draw, with the solver on the CPU and on the
//! GPU (lavapipe in CI): `incise render`, the simulated headset's eye images (`incise xr
//! --simulated-headset`) and the exercise attempt's pictures (`incise exercise`), each
//! checked for the tissue inside the body's projected screen box, the cut surface where
//! the stroke cut, CPU/GPU agreement and a small golden PNG (`tests/golden/`, rewritten
//! with `INCISE_BLESS=1 cargo test --release -p incise --test images_cli`). The preview's
//! window is imaged in tests/preview_xvfb.rs, the exercise's report.html in a headless
//! browser in tests/report_browser.rs.
//!
//! Without a GPU adapter the GPU half is skipped (saying why) unless
//! `INCISE_REQUIRE_GPU=1` (CI).

mod common;

use std::path::Path;

use common::pixels::{
    ScreenBox, assert_devices_agree, assert_golden, count, is_cut, is_tissue, projected_box,
    scene_view, share,
};
use common::{gpu_required, incise, temp_dir, text};
use glam::{Vec2, Vec3};
use incise_xr::RgbaImage;

/// Whether the GPU half of a test runs here: an adapter exists, or `INCISE_REQUIRE_GPU=1`
/// (where a missing one fails the test).
fn gpu_here() -> bool {
    match incise_sim::gpu::GpuContext::new() {
        Ok(_) => true,
        Err(e) if gpu_required() => panic!("INCISE_REQUIRE_GPU=1 but {e}"),
        Err(e) => {
            eprintln!("skipping the GPU half: {e}");
            false
        }
    }
}

const PLATE: &str = "config/plate_cut.ron";
/// plate_cut's incision line on the slab's top (its stroke's start and end).
const PLATE_CUT: (Vec3, Vec3) = (Vec3::new(0.015, 0.02, 0.02), Vec3::new(0.055, 0.02, 0.02));

/// Cut-surface pixels within `r` pixels of the projected segment `a`–`b` (sampled every
/// pixel along it), and the number of pixels in that band.
fn cut_near_segment(img: &RgbaImage, a: Vec2, b: Vec2, r: f32) -> (usize, usize) {
    let (mut cut, mut all) = (0, 0);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ab = b - a;
            let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
            if p.distance(a + ab * t) <= r {
                all += 1;
                cut += is_cut(img.get(x, y)) as usize;
            }
        }
    }
    (cut, all)
}

/// The tissue fills its projected box, the cut shows along the projected incision and
/// almost nowhere else.
fn assert_tissue_and_cut(what: &str, img: &RgbaImage, body: ScreenBox, cut: (Vec2, Vec2)) {
    let tissue = share(img, body, is_tissue);
    assert!(
        tissue > 0.35,
        "{what}: only {:.1} % of the body's screen box {body:?} is tissue",
        tissue * 100.0
    );
    let (near, band) = cut_near_segment(img, cut.0, cut.1, 6.0);
    let all = count(img, is_cut);
    assert!(
        near >= 15,
        "{what}: {near} cut-surface pixels of {band} along the incision {cut:?}"
    );
    assert!(
        all <= near * 2 + 20,
        "{what}: {all} cut-surface pixels, only {near} of them along the incision"
    );
}

/// `incise render SCENE --frame N OUT --size WxH --device DEVICE`; the picture.
fn render(dir: &Path, scene: &str, frame: u32, (w, h): (u32, u32), device: &str) -> RgbaImage {
    let out = dir.join(format!("{device}-{frame}.png"));
    let o = incise(&[
        "render",
        scene,
        "--frame",
        &frame.to_string(),
        out.to_str().unwrap(),
        "--size",
        &format!("{w}x{h}"),
        "--device",
        device,
    ]);
    assert!(
        o.status.success(),
        "render on {device}: {}",
        text(&o.stderr)
    );
    RgbaImage::load_png(&out).unwrap()
}

/// `incise render` of plate_cut after 1.2 s of its stroke: the slab fills its projected
/// box, the cut surface shows along the projected incision (and not before the stroke),
/// the GPU solver's picture matches the CPU's, and the CPU's matches its golden image.
#[test]
fn render_shows_the_tissue_and_its_cut_on_the_cpu_and_the_gpu() {
    let dir = temp_dir("images-render");
    let (w, h) = (192, 128);
    let (view, lo, hi) = scene_view(PLATE, w, h);
    let body = projected_box(&view, lo, hi, w, h);
    let size = Vec2::new(w as f32, h as f32);
    let cut = (
        view.project(PLATE_CUT.0, size).unwrap(),
        // By frame 72 the blade has come 2 cm along the 4 cm line.
        view.project(PLATE_CUT.0.lerp(PLATE_CUT.1, 0.5), size)
            .unwrap(),
    );
    let before = render(&dir, PLATE, 0, (w, h), "cpu");
    assert!(share(&before, body, is_tissue) > 0.35, "rest slab missing");
    assert!(
        count(&before, is_cut) < 10,
        "a cut surface before the stroke"
    );
    let cpu = render(&dir, PLATE, 72, (w, h), "cpu");
    assert_tissue_and_cut("render on the CPU", &cpu, body, cut);
    assert_golden("render_plate_cut_cpu", &cpu);
    if gpu_here() {
        let gpu = render(&dir, PLATE, 72, (w, h), "gpu");
        assert_tissue_and_cut("render on the GPU", &gpu, body, cut);
        assert_devices_agree("render", &cpu, &gpu);
    }
}

/// A small-eyed, narrow-angle simulated headset on plate_cut: the controller draws the scene's incision
/// with the trigger held, both eyes of display frame 120 (1.67 s) are saved.
const XR_SCRIPT: &str = r#"(
    display_hz: 72.0,
    duration: 1.7,
    eye_size: (180, 160),
    // A narrow field of view (±10°), so the 8 cm slab half a metre away fills the eye.
    fov: (left: -0.18, right: 0.18, up: 0.16, down: -0.16),
    render_every: 1,
    screenshots: [120],
    pacing: Nominal,
    head: [(t: 0.0, position: (0.0, 1.25, -0.05), orientation: (-0.34202, 0.0, 0.0, 0.93969))],
    right: Some(Tool(
        start: 0.1,
        stroke: Incision((
            start: (0.015, 0.02, 0.02),
            end: (0.055, 0.02, 0.02),
            depth: 0.005,
            speed: 0.02,
            approach: 0.005,
        )),
    )),
    trigger: [(0.0, 1.0)],
)"#;

/// `incise xr --simulated-headset` on the CPU and the GPU: each eye shows the slab in
/// its box (the rest bounds through the tray and that eye's pose and field of view) and
/// the cut along the incision; the two devices' eyes agree; the CPU's left eye matches
/// its golden image.
#[test]
fn simulated_headset_eyes_show_the_tissue_and_its_cut_on_the_cpu_and_the_gpu() {
    let dir = temp_dir("images-xr");
    let script = dir.join("headset.ron");
    std::fs::write(&script, XR_SCRIPT).unwrap();
    let eyes = |device: &str| {
        let out = dir.join(device);
        let o = incise(&[
            "xr",
            PLATE,
            "--simulated-headset",
            script.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--device",
            device,
        ]);
        assert!(o.status.success(), "xr on {device}: {}", text(&o.stderr));
        ["left", "right"]
            .map(|e| RgbaImage::load_png(&out.join(format!("eye_{e}_00120.png"))).unwrap())
    };
    // Where the slab and the cut are in each eye.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let parsed = incise::xr::script::HeadsetScript::load(&script).unwrap();
    let scene = incise::scene::load_scene(&root.join(PLATE)).unwrap();
    let built = incise::scene::build_scene(&scene, &root.join(PLATE), None).unwrap();
    let (lo, hi) = built.solver.mesh().rest_bounds();
    let tray = incise_xr::openxr::tray::Tray::for_bounds(lo, hi);
    let head =
        incise_xr::openxr::pose::XrPose::new(parsed.head[0].position, parsed.head[0].orientation);
    let (w, h) = parsed.eye_size;
    let size = Vec2::new(w as f32, h as f32);
    let expected = parsed.eyes(head).map(|(pose, fov)| {
        let view = incise_xr::openxr::eye::eye_view(pose, fov, tray.stage_from_sim());
        let cut = (
            view.project(PLATE_CUT.0, size).unwrap(),
            // 1.57 s of the stroke at 2 cm/s, after its 5 mm approach: about 2.2 cm.
            view.project(PLATE_CUT.0.lerp(PLATE_CUT.1, 0.5), size)
                .unwrap(),
        );
        (projected_box(&view, lo, hi, w, h), cut)
    });
    let cpu = eyes("cpu");
    for (img, (body, cut)) in cpu.iter().zip(expected) {
        assert_tissue_and_cut("xr eye on the CPU", img, body, cut);
    }
    assert_golden("xr_plate_cut_left_eye_cpu", &cpu[0]);
    if gpu_here() {
        let gpu = eyes("gpu");
        for (i, (img, (body, cut))) in gpu.iter().zip(expected).enumerate() {
            assert_tissue_and_cut("xr eye on the GPU", img, body, cut);
            assert_devices_agree("xr eye", &cpu[i], img);
        }
    }
}
