//! Issue 21: a scene's `haptic_contact` picks how a hand-held tool is coupled to the
//! Nakao body (PHYSICS.md §2.6). A probe lowered onto the plate, pressed 3 mm in and
//! lifted 2 mm clear: with `GodObject` (Zilles & Salisbury 1995) the tissue pushes the
//! tool back out while it is in and lets go once it is out; the default `NearestNode`
//! spring pulls the lifted tool back down to the node it holds. Both the frame-rate body
//! and the 1 kHz haptic-thread body follow the scene's choice.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use incise::scene::load_scene;
use incise::sim_body::{OpenOptions, ToolInput, open};
use incise_sim::contact::ToolPose;

/// The plate scene with `contact` as its `haptic_contact`, written to a temp file named
/// with `tag` (tests run at once must not share one).
fn plate_scene(contact: &str, tag: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("config/plate_cut_nakao.ron")).unwrap();
    let anchor = "cut: (subdivision: Adaptive),";
    assert!(text.contains(anchor), "plate scene changed");
    let text = text.replace(anchor, &format!("{anchor} haptic_contact: {contact},"));
    let dir = std::env::temp_dir().join(format!("incise-probe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("plate_{contact}_{tag}.ron"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The force on the probe (z, N) at each height of its path (mm above the plate's top),
/// held there for `hold` frames; `haptic_rate`: the 1 kHz thread body.
fn press(contact: &str, path_mm: &[f64], hold: usize, haptic_rate: Option<f64>) -> Vec<f32> {
    let tag = if haptic_rate.is_some() {
        "haptic"
    } else {
        "frame"
    };
    let scene_path = plate_scene(contact, tag);
    let opts = OpenOptions {
        haptic_rate,
        quiet: true,
        ..OpenOptions::default()
    };
    let (mut body, _) = open(&load_scene(&scene_path).unwrap(), &scene_path, &opts).unwrap();
    let top = body
        .surface()
        .positions
        .iter()
        .map(|p| p.z)
        .fold(f32::MIN, f32::max);
    // The blade's coupling point is the middle of its 8 mm edge, which hangs below the
    // tool's origin: 4 mm above the point.
    let at = |mm: f64| ToolInput::Hand {
        pose: ToolPose {
            position: Vec3::new(0.011, 0.013, top + 0.004 + mm as f32 * 1e-3),
            rotation: Quat::IDENTITY,
        },
        engaged: false,
    };
    let mut forces = Vec::new();
    for &mm in path_mm {
        for _ in 0..hold {
            body.step(&at(mm)).unwrap();
        }
        forces.push(body.tool_force().unwrap().z);
    }
    forces
}

/// Down from 3 mm above to 3 mm in, then up to 2 mm above.
const PATH_MM: [f64; 9] = [3.0, 2.0, 1.0, 0.0, -1.0, -2.0, -3.0, 0.5, 2.0];

fn check(contact_forces: &[f32], nearest_forces: &[f32], what: &str) {
    eprintln!("{what}: god object {contact_forces:?} N, nearest node {nearest_forces:?} N");
    let pressed = contact_forces[6];
    assert!(
        pressed > 0.05,
        "{what}: the god object did not push the pressed probe out: {pressed} N"
    );
    assert!(
        contact_forces.iter().all(|f| *f >= 0.0),
        "{what}: the god object pulled the probe: {contact_forces:?}"
    );
    assert_eq!(
        contact_forces[8], 0.0,
        "{what}: the god object still holds the lifted probe"
    );
    assert!(
        nearest_forces[8] < -0.01,
        "{what}: the nearest-node spring did not hold the lifted probe: {} N",
        nearest_forces[8]
    );
}

#[test]
fn frame_rate_body_couples_the_probe_as_the_scene_says() {
    let god = press("GodObject", &PATH_MM, 1, None);
    let nearest = press("NearestNode", &PATH_MM, 1, None);
    check(&god, &nearest, "frame rate");
}

/// Each height is held six 10 ms frames, so that the thread has looped at the new pose
/// (some 50 loops) on a loaded machine before the force is read.
#[test]
fn haptic_thread_couples_the_probe_as_the_scene_says() {
    let god = press("GodObject", &PATH_MM, 6, Some(1000.0));
    let nearest = press("NearestNode", &PATH_MM, 6, Some(1000.0));
    check(&god, &nearest, "haptic thread");
}
