//! Offscreen rendering on any adapter (lavapipe in CI), issue 6 tests 1–3: golden images
//! of the rest intestine, a torn bar and the stress overlay (perceptual tolerance, a diff
//! image on failure; the tissue and the cut surface compared as masks, issue 33), the cut
//! surface visible where the tissue tore, and the GPU skin equal to its barycentric
//! combination after a large deformation.
//!
//! Without an adapter the tests print why and pass, unless the GPU is required
//! (`INCISE_REQUIRE_GPU=1`, or `CI` set with it unset): then they fail.
//! `INCISE_BLESS=pictures` (or `all`) rewrites the stored images instead of comparing
//! (inspect them before committing; refused under CI).

mod common;

use common::device;
use common::masks::{GOLDEN_MASKS, MaskCheck, mask_failures};

use std::path::PathBuf;

use glam::{UVec3, Vec2, Vec3};
use incise_sim::generate::{IntestineParams, block, intestine};
use incise_sim::grab::Grab;
use incise_sim::selection::NodeSelection;
use incise_sim::skin::Skin;
use incise_sim::{Material, Solver, SolverParams, TetMesh};
use incise_xr::compare::{Tolerance, compare};
use incise_xr::frame::MATERIAL_IDS;
use incise_xr::{
    BodyState, Camera, OffscreenRenderer, Overlays, RenderSettings, RgbaImage, ShadingMode,
    UncutBody, View,
};

const SIZE: (u32, u32) = (320, 240);

/// The body of `solver` as the renderer sees it (host positions, von Mises heat);
/// `pinned` lists its pinned nodes.
fn solver_state<'a>(solver: &'a Solver, pinned: &'a [u32]) -> BodyState<'a> {
    BodyState {
        positions: solver.positions(),
        device_displacements: None,
        cut: solver.cut(),
        heat: solver.von_mises(),
        pinned,
    }
}

/// The bar's cut threshold, Pa.
// Cauchy von Mises (twice the seed's eq. 3 value, 6 kPa, at small strain).
const BAR_THRESHOLD: f32 = 12e3;

/// Compare with `tests/golden/NAME.png` (`INCISE_BLESS=pictures` writes it instead): the
/// perceptual difference, and each of `masks` (the tissue, the cut surface) where the
/// golden has it; on failure write the image and a diff beside the test binaries and
/// fail naming them and every failed check.
fn check_golden(name: &str, img: &RgbaImage, masks: &[MaskCheck]) {
    let golden = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("tests/golden/{name}.png"));
    if incise_test_gate::bless(incise_test_gate::Bless::Pictures) {
        img.save_png(&golden).unwrap();
        eprintln!("updated {}", golden.display());
        return;
    }
    let reference = RgbaImage::load_png(&golden).unwrap_or_else(|e| {
        panic!("{e}: run with INCISE_BLESS=pictures to create the golden image, then inspect it")
    });
    let c = compare(img, &reference, Tolerance::default()).unwrap();
    let whole = (!c.passed).then(|| format!("{name} differs from {}: {c}", golden.display()));
    let failures: Vec<String> = whole
        .into_iter()
        .chain(mask_failures(name, &reference, img, masks))
        .collect();
    if !failures.is_empty() {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
        let (actual, diff) = (
            dir.join(format!("{name}.actual.png")),
            dir.join(format!("{name}.diff.png")),
        );
        img.save_png(&actual).unwrap();
        c.diff.save_png(&diff).unwrap();
        panic!(
            "{}; see {} and {} (if the change is meant, INCISE_BLESS=pictures rewrites it)",
            failures.join("\n"),
            actual.display(),
            diff.display()
        );
    }
}

fn id_colour(name: &str) -> [u8; 3] {
    MATERIAL_IDS.iter().find(|(n, _)| *n == name).unwrap().1
}

/// Pixels of `img` (in material-id shading) within `(lo, hi)` showing material `name`.
fn count_material(img: &RgbaImage, name: &str, lo: Vec2, hi: Vec2) -> usize {
    let id = id_colour(name);
    let mut n = 0;
    for y in 0..img.height {
        for x in 0..img.width {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                continue;
            }
            let c = img.get(x, y);
            if (0..3).all(|k| (c[k] as i32 - id[k] as i32).abs() < 40) {
                n += 1;
            }
        }
    }
    n
}

fn rest_intestine() -> (TetMesh, Skin) {
    let (raw, surface) = intestine(&IntestineParams::default());
    let mesh = TetMesh::from_raw(raw).unwrap().0;
    let skin = Skin::embed(&mesh, surface);
    (mesh, skin)
}

/// An 8 × 2 × 2 cm bar pinned at x = 0 and pulled along +x (serial CPU solver, so the
/// result is the same on every machine).
fn tearing_bar() -> (Solver, Skin) {
    let raw = block(
        Vec3::new(0.0, -0.01, -0.01),
        Vec3::new(0.08, 0.02, 0.02),
        UVec3::new(16, 4, 4),
    );
    let mesh = TetMesh::from_raw(raw).unwrap().0;
    let skin = Skin::from_boundary(&mesh);
    let params = SolverParams {
        substeps: 30,
        gravity: Vec3::ZERO,
        threads: 1,
        release_threshold: Some(BAR_THRESHOLD),
        ..SolverParams::default()
    };
    let material = Material {
        youngs_modulus: 20e3,
        poisson_ratio: 0.4,
        density: 1000.0,
    };
    let mut s = Solver::new(mesh, material, params).unwrap();
    let rest = s.mesh().rest_positions.clone();
    let side = |x: f32, normal: Vec3| NodeSelection::PlaneSide {
        point: Vec3::new(x, 0.0, 0.0),
        normal,
    };
    s.pin(&side(0.001, -Vec3::X).select(&rest).unwrap());
    s.add_grab(Grab {
        nodes: side(0.079, Vec3::X).select(&rest).unwrap(),
        waypoints: vec![Vec3::new(0.06, 0.0, 0.0)],
        speed: 0.1,
        start_time: 0.0,
    });
    (s, skin)
}

fn bar_view() -> View {
    let cam = Camera::framing(
        Vec3::new(0.0, -0.012, -0.012),
        Vec3::new(0.14, 0.012, 0.012),
        -1.2,
        0.55,
    );
    cam.view(SIZE.0 as f32 / SIZE.1 as f32)
}

fn step(s: &mut Solver, frames: usize) {
    for _ in 0..frames {
        s.step_frame().unwrap();
    }
}

#[test]
fn golden_rest_intestine() {
    let Some(dev) = device() else { return };
    let (mesh, skin) = rest_intestine();
    let body = UncutBody::new(&mesh);
    let state = body.state(&mesh.rest_positions);
    let (lo, hi) = mesh.rest_bounds();
    let mut cam = Camera::framing(lo, hi, -1.1, 0.6);
    cam.zoom(0.72);
    let view = cam.view(SIZE.0 as f32 / SIZE.1 as f32);
    let mut r = OffscreenRenderer::new(&dev, &mesh, &skin, SIZE, 1).unwrap();
    let img = r
        .render_image(&state, &RenderSettings::default(), &view)
        .unwrap();
    check_golden("rest_intestine", &img, &GOLDEN_MASKS);
    // Nothing is cut at rest: no cut-surface pixels anywhere.
    let ids = RenderSettings {
        shading: ShadingMode::MaterialIds,
        ..RenderSettings::default()
    };
    let img = r.render_image(&state, &ids, &view).unwrap();
    let all = (Vec2::ZERO, Vec2::new(SIZE.0 as f32, SIZE.1 as f32));
    assert_eq!(count_material(&img, "cut", all.0, all.1), 0);
    assert!(count_material(&img, "skin", all.0, all.1) > 5000);
}

#[test]
fn golden_torn_bar_shows_the_cut_where_it_tore() {
    let Some(dev) = device() else { return };
    let (mut s, skin) = tearing_bar();
    let pinned = s.pinned_nodes();
    let view = bar_view();
    let mut r = OffscreenRenderer::new(&dev, s.mesh(), &skin, SIZE, 1).unwrap();
    let ids = RenderSettings {
        shading: ShadingMode::MaterialIds,
        ..RenderSettings::default()
    };
    let full = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    // (a) Before the tear: no cut surface on screen.
    let before = r
        .render_image(&solver_state(&s, &pinned), &ids, &view)
        .unwrap();
    assert_eq!(count_material(&before, "cut", Vec2::ZERO, full), 0);
    // The bar starts tearing at its pinned end in frame 25 (frames counted from 0).
    step(&mut s, 28);
    assert!(
        s.cut().released_count() > 0,
        "the bar should have torn by frame 27"
    );
    let state = solver_state(&s, &pinned);
    let img = r
        .render_image(&state, &RenderSettings::default(), &view)
        .unwrap();
    check_golden("torn_bar", &img, &GOLDEN_MASKS);
    // (b) The cut surface appears, and where the released tets are on screen.
    let after = r.render_image(&state, &ids, &view).unwrap();
    let released: Vec<Vec2> = (0..s.mesh().tet_count())
        .filter(|&t| !s.cut().is_live(t))
        .filter_map(|t| {
            let c = s.mesh().tets[t]
                .iter()
                .map(|&n| s.positions()[n as usize])
                .sum::<Vec3>()
                / 4.0;
            view.project(c, full)
        })
        .collect();
    let lo = released.iter().fold(full, |a, &b| a.min(b)) - Vec2::splat(12.0);
    let hi = released.iter().fold(Vec2::ZERO, |a, &b| a.max(b)) + Vec2::splat(12.0);
    let near = count_material(&after, "cut", lo, hi);
    let anywhere = count_material(&after, "cut", Vec2::ZERO, full);
    assert!(
        near >= 50,
        "only {near} cut-surface pixels near the tear ({lo} – {hi})"
    );
    assert!(
        near as f32 >= 0.9 * anywhere as f32,
        "{near} of {anywhere} cut pixels near the tear"
    );
    // The skin over released tets is gone: fewer skin triangles are drawn.
    assert!(r.renderer.visible_skin_triangles() < skin.surface.triangles.len() as u32);
    assert!(r.renderer.cut_faces() > 0);
}

#[test]
fn golden_stress_overlay() {
    let Some(dev) = device() else { return };
    let (mut s, skin) = tearing_bar();
    let pinned = s.pinned_nodes();
    step(&mut s, 24);
    assert_eq!(s.cut().released_count(), 0, "still whole at frame 23");
    let mut r = OffscreenRenderer::new(&dev, s.mesh(), &skin, SIZE, 1).unwrap();
    let settings = RenderSettings {
        overlays: Overlays {
            stress: true,
            pinned: true,
            ..Overlays::default()
        },
        stress_max: BAR_THRESHOLD,
        ..RenderSettings::default()
    };
    let img = r
        .render_image(&solver_state(&s, &pinned), &settings, &bar_view())
        .unwrap();
    // The heat map's colours are neither skin nor cut surface: the whole picture only.
    check_golden("stress_overlay", &img, &[]);
}

#[test]
fn gpu_skin_equals_its_barycentric_combination_after_a_large_deformation() {
    let Some(dev) = device() else { return };
    let (mesh, skin) = rest_intestine();
    // Twist about x by up to 90°, stretch by 40 % and bend: large and far from affine.
    let deformed: Vec<Vec3> = mesh
        .rest_positions
        .iter()
        .map(|p| {
            let a = p.x * 10.0;
            let (s, c) = a.sin_cos();
            Vec3::new(
                1.4 * p.x,
                c * p.y - s * p.z,
                s * p.y + c * p.z + 3.0 * p.x * p.x,
            )
        })
        .collect();
    let body = UncutBody::new(&mesh);
    let state = body.state(&deformed);
    let mut r = OffscreenRenderer::new(&dev, &mesh, &skin, (64, 48), 1).unwrap();
    let view = Camera::framing(Vec3::splat(-0.2), Vec3::splat(0.2), 0.0, 0.3).view(4.0 / 3.0);
    r.render(&state, &RenderSettings::default(), &[view]);
    let gpu = r.renderer.read_skin_positions().unwrap();
    assert_eq!(gpu.len(), skin.embedding.len());
    let mut worst = 0.0f32;
    for (g, e) in gpu.iter().zip(&skin.embedding) {
        let cpu: Vec3 = (0..4)
            .map(|c| e.bary[c] * deformed[e.nodes[c] as usize])
            .sum();
        worst = worst.max((*g - cpu).abs().max_element());
    }
    assert!(worst <= 1e-6, "largest difference {worst} m");
    // And the skin really moved: the deformation is large.
    let moved = gpu
        .iter()
        .zip(&skin.surface.positions)
        .map(|(g, p)| (*g - *p).length())
        .fold(0.0f32, f32::max);
    assert!(moved > 0.05, "{moved}");
}

/// Stereo offscreen (the Quest benchmark and screenshots): both eyes are drawn, each into
/// its own target, and they differ by the eyes' separation. (With one 2-layer array
/// texture, lavapipe drew the second eye into layer 0 and left layer 1 blank.)
#[test]
fn both_eyes_of_a_stereo_target_are_drawn() {
    let Some(dev) = device() else {
        return;
    };
    let mesh = TetMesh::from_raw(block(Vec3::ZERO, Vec3::splat(0.02), UVec3::new(2, 2, 2)))
        .unwrap()
        .0;
    let skin = Skin::from_boundary(&mesh);
    let body = UncutBody::new(&mesh);
    let state = body.state(&mesh.rest_positions);
    let (lo, hi) = mesh.rest_bounds();
    let centre = Camera::framing(lo, hi, -1.0, 0.5).view(4.0 / 3.0);
    let right = centre.view.inverse().x_axis.truncate();
    let eyes: Vec<View> = [-0.005f32, 0.005]
        .iter()
        .map(|&d| View {
            view: centre.view * glam::Mat4::from_translation(-right * d),
            proj: centre.proj,
        })
        .collect();
    let mut r = OffscreenRenderer::new(&dev, &mesh, &skin, SIZE, 2).unwrap();
    r.render(&state, &RenderSettings::default(), &eyes);
    let (left, right_img) = (r.read_image(0).unwrap(), r.read_image(1).unwrap());
    let background = left.pixels[..4].to_vec();
    let drawn = |img: &RgbaImage| {
        img.pixels
            .chunks(4)
            .filter(|p| *p != &background[..])
            .count()
    };
    assert!(drawn(&left) > 1000, "the left eye is blank");
    assert!(drawn(&right_img) > 1000, "the right eye is blank");
    assert_ne!(left.pixels, right_img.pixels, "the eyes see the same image");
    assert!(r.read_image(2).is_err(), "there is no third eye");
}

/// A 60 × 40 picture: a skin-pink 40 × 20 slab, and on it a 24 × 4 slot of `colour`
/// whose top left corner is at (`x`, `y`), if any.
fn slab_with_slot(slot: Option<([u8; 4], u32, u32)>) -> RgbaImage {
    let mut img = RgbaImage::filled(60, 40, [40, 44, 52, 255]);
    let mut fill = |(x0, y0): (u32, u32), (w, h): (u32, u32), c: [u8; 4]| {
        for (x, y) in (x0..x0 + w).flat_map(|x| (y0..y0 + h).map(move |y| (x, y))) {
            img.set(x, y, c);
        }
    };
    fill((10, 10), (40, 20), [200, 140, 130, 255]);
    if let Some((colour, x, y)) = slot {
        fill((x, y), (24, 4), colour);
    }
    img
}

/// The golden masks (no GPU needed): a slot drawn as in the golden, or a pixel off, passes;
/// one missing, drawn in the skin's colour or moved across or along itself fails on the
/// cut surface.
#[test]
fn golden_masks_fail_a_cut_missing_recoloured_or_moved() {
    let (skin, cut) = ([200, 140, 130, 255], [80, 15, 15, 255]);
    let golden = slab_with_slot(Some((cut, 18, 16)));
    let fails = |img: RgbaImage| mask_failures("slab", &golden, &img, &GOLDEN_MASKS);
    assert_eq!(
        fails(slab_with_slot(Some((cut, 18, 16)))),
        Vec::<String>::new()
    );
    assert_eq!(
        fails(slab_with_slot(Some((cut, 19, 17)))),
        Vec::<String>::new()
    );
    let broken = [
        ("missing", None),
        ("in the skin's colour", Some((skin, 18, 16))),
        ("3 px across", Some((cut, 18, 19))),
        ("4 px along", Some((cut, 22, 16))),
    ];
    for (what, slot) in broken {
        let f = fails(slab_with_slot(slot));
        assert!(
            f.iter().any(|m| m.contains("the cut surface")),
            "a cut {what} passes: {f:?}"
        );
    }
}
