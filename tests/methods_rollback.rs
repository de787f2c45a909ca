//! Issue 20, item 3: a frame that fails (a NaN injected before it) leaves the body bit for
//! bit at its last completed frame, through the `SimBody` interface — for the Nakao body
//! on a frame whose cut remodels the mesh (its whole model is restored) and on one without
//! a cut (only positions, velocities and time are saved each frame), and for the
//! rheological body. `Outcome::hash` covers the Nakao model's every bit (nodes, tets,
//! springs, masses, cut faces, positions, velocities, time) and the rheological body's
//! positions, velocities, Voigt ratios and time (saved each frame instead of a clone).

use std::path::Path;

use incise::scene::load_scene;
use incise::sim_body::{DeviceChoice, Fault, OpenOptions, Outcome, SimBody, ToolInput, open};

/// The body of `scene`, opened on the CPU.
fn body(scene: &str) -> Box<dyn SimBody> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let opts = OpenOptions {
        device: DeviceChoice::Cpu,
        quiet: true,
        ..OpenOptions::default()
    };
    open(&load_scene(&path).unwrap(), &path, &opts).unwrap().0
}

/// The outcome after each of `frames` scripted frames (index 0: before the first).
fn outcomes(scene: &str, frames: usize) -> Vec<Outcome> {
    let mut b = body(scene);
    let mut out = vec![b.outcome().unwrap()];
    for _ in 0..frames {
        b.step(&ToolInput::Script).unwrap();
        out.push(b.outcome().unwrap());
    }
    out
}

/// Step `scene` `frames` frames, inject a NaN, step once more: the step fails and the
/// body is where it was, bit for bit (and equal to the reference run at that frame).
fn rolls_back_at(scene: &str, frames: usize, reference: &[Outcome]) {
    let mut b = body(scene);
    for _ in 0..frames {
        b.step(&ToolInput::Script).unwrap();
    }
    let before = b.outcome().unwrap();
    assert_eq!(before, reference[frames], "{scene}: the runs replay alike");
    b.inject(Fault::Nan).unwrap();
    let err = b.step(&ToolInput::Script).unwrap_err();
    assert!(err.to_string().contains("rolled back"), "{err}");
    assert_eq!(
        b.outcome().unwrap(),
        before,
        "{scene}: frame {frames} rolled back"
    );
}

/// Node count of a Nakao outcome ("N nodes, T tets").
fn nodes(o: &Outcome) -> usize {
    o.summary.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn a_failed_nakao_frame_rolls_back_bit_for_bit_with_and_without_a_cut() {
    let scene = "config/plate_cut_nakao.ron";
    let reference = outcomes(scene, 60);
    // Frame 10 is before the blade starts (0.2 s): no cut, only the state is saved.
    assert_eq!(nodes(&reference[11]), nodes(&reference[10]));
    rolls_back_at(scene, 10, &reference);
    // The first two frames whose cut adds nodes: the failed frame remodels before the
    // NaN is found, and the whole model must come back (at the second, as the first
    // remodelling frame left it).
    let cuts: Vec<usize> = (20..60)
        .filter(|&f| nodes(&reference[f + 1]) > nodes(&reference[f]))
        .take(2)
        .collect();
    assert_eq!(cuts.len(), 2, "the blade adds nodes twice by frame 60");
    for f in cuts {
        rolls_back_at(scene, f, &reference);
    }
}

#[test]
fn a_failed_rheology_frame_rolls_back_bit_for_bit() {
    let scene = "config/organ_layers.ron";
    let reference = outcomes(scene, 20);
    rolls_back_at(scene, 20, &reference);
}
