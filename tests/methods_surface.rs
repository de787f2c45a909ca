//! Issue 20: what each method's body gives to draw through the `SimBody` interface — the
//! surface (positions, skin triangles, cut triangles) and the heat-map quantity per
//! vertex, named with its unit — follows the method's own physics: XPBD's cut surface
//! appears where the scalpel released tets and its stress is in Pa; the Nakao wound's
//! faces are cut triangles and the tension relaxes along it; the rheological body has no
//! cut and is strained under the indenter.

use std::path::Path;

use incise::scene::load_scene;
use incise::sim_body::{DeviceChoice, OpenOptions, SimBody, ToolInput, open};

/// The body of `scene` after `frames` scripted frames.
fn stepped(scene: &str, frames: u32) -> Box<dyn SimBody> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let opts = OpenOptions {
        device: DeviceChoice::Cpu,
        quiet: true,
        ..OpenOptions::default()
    };
    let (mut body, _) = open(&load_scene(&path).unwrap(), &path, &opts).unwrap();
    for _ in 0..frames {
        body.step(&ToolInput::Script).unwrap();
    }
    body
}

#[test]
fn xpbd_surface_shows_the_cut_and_the_stress_in_pascal() {
    let s = stepped("config/plate_cut.ron", 60).surface();
    let q = s.quantity.unwrap();
    assert_eq!((q.name, q.unit), ("von Mises stress", "Pa"));
    assert_eq!(s.scalar.len(), s.positions.len());
    assert!(!s.triangles.is_empty() && !s.cut_triangles.is_empty());
    assert!(s.scalar.iter().copied().fold(0.0, f32::max) > 100.0);
}

#[test]
fn nakao_surface_has_the_wound_as_cut_triangles_and_its_tension() {
    let before = stepped("config/plate_cut_nakao.ron", 1).surface();
    let after = stepped("config/plate_cut_nakao.ron", 60).surface();
    let q = after.quantity.unwrap();
    assert_eq!((q.name, q.unit), ("spring tension", "N"));
    assert!(before.cut_triangles.is_empty());
    assert!(
        after.cut_triangles.len() > 40,
        "{}",
        after.cut_triangles.len()
    );
    assert_eq!(after.scalar.len(), after.positions.len());
    // The cut faces are not also drawn as skin.
    let skin: std::collections::HashSet<[u32; 3]> = after.triangles.iter().copied().collect();
    assert!(after.cut_triangles.iter().all(|t| !skin.contains(t)));
    // Cutting frees the springs across the wound: the nodes on it are less stretched
    // than the plate's mean under 4 % tension.
    let on_wound: std::collections::HashSet<u32> =
        after.cut_triangles.iter().flatten().copied().collect();
    let mean = |it: &mut dyn Iterator<Item = f32>| {
        let v: Vec<f32> = it.collect();
        v.iter().sum::<f32>() / v.len() as f32
    };
    let wound = mean(&mut on_wound.iter().map(|&n| after.scalar[n as usize]));
    let all = mean(&mut after.scalar.iter().copied());
    assert!(wound < all, "tension on the wound {wound} N, plate {all} N");
}

#[test]
fn rheology_surface_is_uncut_and_strained_under_the_indenter() {
    let rest = stepped("config/organ_layers.ron", 1).surface();
    let pressed = stepped("config/organ_layers.ron", 50).surface();
    let q = pressed.quantity.unwrap();
    assert_eq!((q.name, q.unit), ("edge strain", "1"));
    assert!(pressed.cut_triangles.is_empty() && !pressed.triangles.is_empty());
    let max = |s: &incise::sim_body::Surface| s.scalar.iter().copied().fold(0.0, f32::max);
    // Pressed 2.5 cm into a 15 cm block: edges strained by several per cent.
    assert!(max(&pressed) > 0.02 && max(&pressed) > 10.0 * max(&rest));
}
