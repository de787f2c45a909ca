//! The desktop preview in a real window under Xvfb (issue 6, test 4): it opens, renders
//! at least 30 frames, saves a screenshot of the window and exits cleanly through
//! `--frames`; without a display it refuses with a clear message, and `incise` with no
//! arguments falls back to the headless run.
//!
//! A left-drag in the window (xdotool) cuts the tissue with the mouse scalpel.
//!
//! Needs `xvfb-run` and `xdotool` (scripts/ensure-deps.sh installs them) and a wgpu
//! adapter; without them the window tests print why and pass, unless the GPU is required
//! (`INCISE_REQUIRE_GPU=1`, or `CI` set with it unset; crates/test-gate).

mod common;

use common::pixels::{assert_devices_agree, is_cut, is_tissue, projected_box, scene_view, share};
use common::temp_dir;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

use incise_test_gate::{Need, skip_or_fail};
use incise_xr::RgbaImage;

/// `incise preview ARGS --device cpu --screenshot F` under Xvfb; the screenshot, or `None`
/// (the test is skipped, saying why) without xvfb-run or a GPU adapter unless the GPU is
/// required.
fn preview_screenshot(name: &str, args: &[&str]) -> Option<RgbaImage> {
    preview_screenshot_on(name, args, "cpu")
}

/// [`preview_screenshot`] with the solver on `device`.
fn preview_screenshot_on(name: &str, args: &[&str], device: &str) -> Option<RgbaImage> {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        skip_or_fail(
            Need::Gpu,
            "xvfb-run is not installed (apt-get install xvfb)",
        );
        return None;
    }
    let dir = temp_dir(name);
    let shot = dir.join("window.png");
    let o = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_incise"))
        .arg("preview")
        .args(args)
        .args(["--device", device, "--screenshot"])
        .arg(&shot)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("XDG_RUNTIME_DIR", &dir)
        .output()
        .expect("xvfb-run runs");
    passed_or_skipped(o)?;
    Some(RgbaImage::load_png(&shot).unwrap())
}

#[test]
fn preview_opens_a_window_renders_and_exits_after_n_frames() {
    let Some(img) = preview_screenshot(
        "xvfb",
        &["config/beam_sag.ron", "--frames", "30", "--size", "640x480"],
    ) else {
        return;
    };
    assert_eq!((img.width, img.height), (640, 480));
    // The panel (egui's dark grey) on the left, the scene's background and the beam's
    // skin on the right: the window holds more than one flat colour.
    let mut colours: Vec<[u8; 4]> = img
        .pixels
        .chunks_exact(4)
        .map(|p| [p[0], p[1], p[2], p[3]])
        .collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(
        colours.len() > 50,
        "only {} colours in the window",
        colours.len()
    );
    let reddish = img
        .pixels
        .chunks_exact(4)
        .filter(|p| p[0] as i32 > p[2] as i32 + 40 && p[0] > 90)
        .count();
    assert!(
        reddish > 300,
        "the beam's tissue should be on screen ({reddish} pixels)"
    );
}

/// A preview run's output when it succeeded; `None` (said why) when it found no GPU
/// adapter and the GPU is not required; a failure otherwise.
fn passed_or_skipped(o: std::process::Output) -> Option<std::process::Output> {
    let err = String::from_utf8_lossy(&o.stderr);
    if !o.status.success() && err.contains("no GPU adapter") {
        skip_or_fail(Need::Gpu, err);
        return None;
    }
    assert!(o.status.success(), "preview failed: {err}");
    Some(o)
}

/// The scalpel scene without its own tool and stroke: only the mouse can cut it.
fn untooled_plate(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::copy("config/materials.ron", dir.join("materials.ron")).unwrap();
    let s = std::fs::read_to_string("config/plate_cut.ron").unwrap();
    let plain = format!(
        "{}{}",
        &s[..s.find("    tool: Some(").unwrap()],
        &s[s.find("    duration:").unwrap()..]
    );
    let path = dir.join("plate.ron");
    std::fs::write(&path, plain).unwrap();
    path
}

/// Run the bash `script` (which drives the window with xdotool) under Xvfb in `cwd`,
/// runtime files in `dir`; its output when it succeeded, `None` (said why) when xvfb-run,
/// xdotool or a GPU adapter is missing and the GPU is not required.
fn xdotool_session(script: &str, cwd: &Path, dir: &Path) -> Option<std::process::Output> {
    let have = |tool: &str| {
        Command::new("which")
            .arg(tool)
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !have("xvfb-run") || !have("xdotool") {
        skip_or_fail(Need::Gpu, "xvfb-run or xdotool is not installed");
        return None;
    }
    let o = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24", "bash", "-c", script])
        .current_dir(cwd)
        .env("XDG_RUNTIME_DIR", dir)
        .output()
        .expect("xvfb-run runs");
    passed_or_skipped(o)
}

#[test]
fn a_left_drag_in_the_window_cuts_the_tissue() {
    let dir = temp_dir("xvfb-drag");
    let scene = untooled_plate(&dir);
    let shot = dir.join("drag.png");
    // In the 900 × 600 window the slab's top is around (500, 235) (preview camera, panel
    // on the left). Press there, let the blade sink, drag 15 cm of screen to the lower
    // right, release, then Escape: the last frame is saved and the window closes.
    let script = format!(
        r#"timeout 120 {bin} preview {scene} --frames 100000 --size 900x600 --device cpu --screenshot {shot} &
P=$!
W=$(xdotool search --sync --name "incise preview")
sleep 2
xdotool mousemove --window $W 500 235
sleep 0.5
xdotool mousedown 1
sleep 6
for i in $(seq 0 30); do xdotool mousemove --window $W $((500+i*5)) $((235+i)); sleep 0.2; done
sleep 1
xdotool mouseup 1
sleep 1
xdotool windowfocus $W
sleep 0.5
xdotool key Escape
wait $P"#,
        bin = env!("CARGO_BIN_EXE_incise"),
        scene = scene.display(),
        shot = shot.display(),
    );
    let cwd = Path::new(env!("CARGO_MANIFEST_DIR"));
    if xdotool_session(&script, cwd, &dir).is_none() {
        return;
    }
    let img = RgbaImage::load_png(&shot).unwrap();
    // The cut surface's wet red (the skin is pink: much more green), in the 3D view.
    let cut = (0..img.height)
        .flat_map(|y| (300..img.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get(x, y);
            p[0] > 150 && p[1] < 110 && p[2] < 130
        })
        .count();
    assert!(cut > 200, "no cut surface after the drag ({cut} pixels)");
}

/// The window of `exercise` after 10 frames, 900 × 600 (`name`: its temporary folder).
fn exercise_window(name: &str, exercise: &str) -> Option<RgbaImage> {
    let args = [
        "--exercise",
        exercise,
        "--frames",
        "10",
        "--size",
        "900x600",
    ];
    preview_screenshot(name, &args)
}

/// Pixels of the violet marker line (blue well above green, red between) in the 3D view,
/// right of the panel.
fn plan_pixels(img: &RgbaImage) -> usize {
    (0..img.height)
        .flat_map(|y| (300..img.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get(x, y);
            p[2] as i32 > p[1] as i32 + 60 && p[0] as i32 > p[1] as i32 + 20
        })
        .count()
}

#[test]
fn an_exercise_draws_its_plan_on_the_tissue() {
    let Some(img) = exercise_window("xvfb-exercise", "config/exercises/slab_depth.ron") else {
        return;
    };
    // A 3 cm line 1 mm wide.
    let violet = plan_pixels(&img);
    eprintln!("{violet} violet pixels");
    assert!(
        (60..5000).contains(&violet),
        "the plan line should be on the tissue: {violet} violet pixels"
    );
}

/// Pixels of the scalpel in the 3D view: light neutral grey (a heat map is coloured, the
/// background dark).
fn steel_pixels(img: &RgbaImage) -> usize {
    (0..img.height)
        .flat_map(|y| (300..img.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get(x, y).map(i32::from);
            p[0] > 180 && (p[0] - p[1]).abs() < 15 && (p[1] - p[2]).abs() < 15
        })
        .count()
}

/// The Nakao plate's scripted cut (from 0.2 s, 10 ms frames) shows the blade that makes
/// it, as the XPBD preview shows its scripted scalpel: half-way through the stroke the
/// scalpel is drawn at the wound's front; the layered organ's indenter is no scalpel.
#[test]
fn the_nakao_preview_draws_the_scripted_blade() {
    let args = [
        "config/plate_cut_nakao.ron",
        "--frames",
        "50",
        "--size",
        "900x600",
    ];
    let Some(img) = preview_screenshot("xvfb-nakao-script", &args) else {
        return;
    };
    let steel = steel_pixels(&img);
    eprintln!("{steel} steel pixels");
    assert!(steel > 500, "no scripted blade drawn: {steel} steel pixels");
    let args = [
        "config/organ_layers.ron",
        "--frames",
        "30",
        "--size",
        "900x600",
    ];
    let img = preview_screenshot("xvfb-rheology-script", &args).unwrap();
    let steel = steel_pixels(&img);
    assert!(
        steel < 50,
        "a scalpel drawn on the indented organ: {steel} steel pixels"
    );
}

/// A Nakao exercise opens in the preview with its plan drawn on the plate (the
/// panel offers its attempts): the same violet line as an XPBD exercise's.
#[test]
fn a_nakao_exercise_draws_its_plan_in_the_preview() {
    let Some(img) = exercise_window(
        "xvfb-exercise-nakao",
        "config/exercises/plate_line_nakao.ron",
    ) else {
        return;
    };
    let violet = plan_pixels(&img);
    eprintln!("{violet} violet pixels");
    assert!(
        (60..5000).contains(&violet),
        "the plan line should be on the plate: {violet} violet pixels"
    );
    // The mouse's scalpel, drawn where it waits above the plate.
    let steel = steel_pixels(&img);
    assert!(steel > 500, "no scalpel drawn: {steel} steel pixels");
    // The blade is the mouse's from the start: the scene's scripted cut (from 0.2 s) does
    // not open the plate before an attempt.
    let o = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_incise"))
        .args([
            "preview",
            "--exercise",
            "config/exercises/plate_line_nakao.ron",
        ])
        .args(["--frames", "50", "--device", "cpu"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("XDG_RUNTIME_DIR", temp_dir("xvfb-exercise-nakao-script"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("cut added 0 nodes and 0 tets"), "{out}");
}

#[test]
fn without_a_display_preview_refuses_and_the_default_runs_headless() {
    let o = Command::new(env!("CARGO_BIN_EXE_incise"))
        .args(["preview", "config/beam_sag.ron"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("no display") && err.contains("incise run"),
        "{err}"
    );
    // No arguments: the headless default run starts and says why (stopped once it has).
    let dir = temp_dir("default");
    let mut child = Command::new(env!("CARGO_BIN_EXE_incise"))
        .current_dir(&dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let _ = child.kill();
    let _ = child.wait();
    assert!(
        first.contains("no display") && first.contains("headless"),
        "{first}"
    );
}

/// The window's width taken by the side panel: the first column of the bottom row that
/// has the 3D view's background colour (the top-right pixel).
fn panel_width(img: &RgbaImage) -> u32 {
    let bg = img.get(img.width - 1, 0);
    (0..img.width)
        .find(|&x| img.get(x, img.height - 1)[..3] == bg[..3])
        .expect("no 3D view in the window")
}

/// The right part of `img` from column `x0` on.
fn crop_right(img: &RgbaImage, x0: u32) -> RgbaImage {
    let mut out = RgbaImage::filled(img.width - x0, img.height, [0, 0, 0, 255]);
    for y in 0..img.height {
        for x in x0..img.width {
            out.set(x - x0, y, img.get(x, y));
        }
    }
    out
}

/// The preview's window after 72 frames of plate_cut's stroke, with the solver on the
/// CPU and on the GPU (issue 18: the GPU path drew only the scalpel): the slab fills its
/// box (the preview camera, the view shifted right by half the panel), the cut surface
/// shows, and the two 3D views agree.
#[test]
fn preview_window_shows_the_tissue_and_its_cut_on_the_cpu_and_the_gpu() {
    let args = [
        "config/plate_cut.ron",
        "--frames",
        "72",
        "--size",
        "640x400",
    ];
    let Some(cpu) = preview_screenshot_on("xvfb-cpu", &args, "cpu") else {
        return;
    };
    let (w, h) = (cpu.width, cpu.height);
    let panel = panel_width(&cpu);
    assert!((100..w / 2).contains(&panel), "panel {panel} px wide");
    let (_, lo, hi) = scene_view("config/plate_cut.ron", w, h);
    // The preview's camera: the default one zoomed out 1.3× (src/preview/mod.rs), its
    // picture centred in the part of the window the panel leaves free.
    let scene = incise::scene::load_scene(std::path::Path::new("config/plate_cut.ron")).unwrap();
    let built =
        incise::scene::build_scene(&scene, std::path::Path::new("config/plate_cut.ron"), None)
            .unwrap();
    let mut cam = incise::pictures::screenshots::default_camera(built.solver.mesh());
    cam.zoom(1.3);
    let mut view = cam.view(w as f32 / h as f32);
    let shift = panel as f32 / w as f32;
    view.proj = glam::Mat4::from_translation(glam::Vec3::new(shift, 0.0, 0.0)) * view.proj;
    let body = projected_box(&view, lo, hi, w, h);
    let check = |what: &str, img: &RgbaImage| {
        let tissue = share(img, body, is_tissue);
        assert!(
            tissue > 0.35,
            "{what}: {:.1} % tissue in {body:?}",
            tissue * 100.0
        );
        let cut = share(img, body, is_cut) * body.area() as f64;
        assert!(cut > 30.0, "{what}: {cut} cut-surface pixels");
    };
    check("preview on the CPU", &cpu);
    let gpu = preview_screenshot_on("xvfb-gpu", &args, "gpu").expect("the CPU preview ran");
    check("preview on the GPU", &gpu);
    assert_devices_agree(
        "preview 3D view",
        &crop_right(&cpu, panel),
        &crop_right(&gpu, panel),
    );
}

/// The files in `dir` whose names start with `stem` and end with `ext`.
fn saved(dir: &std::path::Path, stem: &str, ext: &str) -> Vec<std::path::PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name.starts_with(stem) && name.ends_with(ext)
        })
        .collect()
}

/// The panel on a Nakao body (clicked with xdotool at its buttons' places in the 900 ×
/// 600 window: the same panel as an XPBD body's, without the XPBD settings) saves a
/// `.vtu` and a screenshot, turns the heat map off and resets the plate to the scene as
/// loaded.
#[test]
fn the_panel_saves_toggles_the_heat_map_and_resets_a_nakao_body() {
    let dir = temp_dir("xvfb-method-panel");
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/plate_cut_nakao.ron");
    let last = dir.join("last.png");
    // Save .vtu (132, 82), Screenshot (48, 82), the heat map box (15, 468), Reset
    // (141, 59), then Escape at once (the fresh body a few frames old).
    let script = format!(
        r#"timeout 120 {bin} preview {scene} --frames 100000 --size 900x600 --screenshot {last} &
P=$!
W=$(xdotool search --sync --name "incise preview")
sleep 3
click() {{ xdotool mousemove --window $W $1 $2; sleep 0.3; xdotool click 1; sleep 1; }}
click 132 82
click 48 82
click 15 468
click 141 59
xdotool windowfocus $W
xdotool key Escape
wait $P"#,
        bin = env!("CARGO_BIN_EXE_incise"),
        scene = scene.display(),
        last = last.display(),
    );
    let Some(o) = xdotool_session(&script, &dir, &dir) else {
        return;
    };
    let vtu = saved(&dir.join("out/preview"), "plate_cut_nakao_f", ".vtu");
    assert_eq!(vtu.len(), 1, "no .vtu saved: {vtu:?}");
    assert!(
        std::fs::read_to_string(&vtu[0])
            .unwrap()
            .contains("<VTKFile")
    );
    let shots = saved(&dir.join("screenshots"), "plate_cut_nakao_f", ".png");
    assert_eq!(shots.len(), 1, "no screenshot saved: {shots:?}");
    // Orange heat map (green well above blue) in the screenshot, the pink skin after the
    // box was cleared.
    let heat = |img: &RgbaImage| {
        (0..img.height)
            .flat_map(|y| (300..img.width).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let p = img.get(x, y);
                p[1] as i32 - p[2] as i32 > 40
            })
            .count()
    };
    let shot = RgbaImage::load_png(&shots[0]).unwrap();
    let end = RgbaImage::load_png(&last).unwrap();
    assert!(
        heat(&shot) > 5000 && heat(&end) < 100,
        "heat-map pixels {} with the box, {} without",
        heat(&shot),
        heat(&end)
    );
    // Reset: the body at the end is a fresh one, younger than the screenshot's.
    let name = shots[0].file_stem().unwrap().to_string_lossy().into_owned();
    let shot_frame: u64 = name.rsplit('f').next().unwrap().parse().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    let completed: u64 = out
        .split("completed ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no summary: {out}"));
    assert!(
        completed < shot_frame,
        "{completed} frames at the end against {shot_frame} at the screenshot: no reset"
    );
}
