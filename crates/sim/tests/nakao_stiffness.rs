//! Issue 21: a region the cutter subdivides keeps the stiffness and the tension of the
//! uncut model (PHYSICS.md §2.1–2.4, docs/physics-notes.md "Nakao"). A block clamped at
//! both ends is stretched; its end reaction is measured at rest (the pre-tension of eq. 3)
//! and at a 1 % stretch, before and after a cut through its middle along the load, which
//! carries no stress across it in a uniaxial pull.

use glam::{DVec3, UVec3, Vec3};
use incise_sim::TetMesh;
use incise_sim::generate::block;
use incise_sim::mass_spring::{AxisMask, MassSpringModel, MassSpringParams, StiffnessLaw, Tension};
use incise_sim::nakao_cut::{BladePose, CutParams, Cutter};

/// Block length (load axis x), width and depth, m.
const SIZE: [f64; 3] = [0.06, 0.02, 0.02];
/// Stretch of the loaded end, m (1 % strain).
const STRETCH: f64 = 0.0006;

fn block_model(law: StiffnessLaw) -> MassSpringModel {
    let size = Vec3::new(SIZE[0] as f32, SIZE[1] as f32, SIZE[2] as f32);
    let (mesh, _) = TetMesh::from_raw(block(Vec3::ZERO, size, UVec3::new(12, 4, 4))).unwrap();
    let params = MassSpringParams {
        stiffness_law: law,
        gravity: DVec3::ZERO,
        tension: Tension::Uniform(0.04),
        damping: 0.2,
        ..MassSpringParams::default()
    };
    let mut m = MassSpringModel::new(&mesh, params).unwrap();
    let ends: Vec<u32> = (0..m.node_count() as u32)
        .filter(|&i| {
            let x = m.positions()[i as usize].x;
            !(1e-6..=SIZE[0] - 1e-6).contains(&x)
        })
        .collect();
    m.fix(&ends, AxisMask::ALL).unwrap();
    m
}

fn loaded_end(m: &MassSpringModel) -> Vec<u32> {
    (0..m.node_count() as u32)
        .filter(|&i| m.reference_positions()[i as usize].x > SIZE[0] - 1e-6)
        .collect()
}

/// Settle and return the pull the loaded end takes, N (x component of the springs' force
/// on it, reversed).
fn settled_reaction(m: &mut MassSpringModel) -> f64 {
    for _ in 0..400 {
        m.advance(0.01);
        if m.kinetic_energy() < 1e-16 {
            break;
        }
    }
    assert!(
        m.kinetic_energy() < 1e-12,
        "did not settle: {}",
        m.kinetic_energy()
    );
    -loaded_end(m)
        .iter()
        .map(|&i| m.spring_force(i as usize).x)
        .sum::<f64>()
}

/// (pre-tension reaction, stiffness ΔF/Δx) of `m`; leaves the end stretched.
fn tension_and_stiffness(m: &mut MassSpringModel) -> (f64, f64) {
    let f0 = settled_reaction(m);
    for i in loaded_end(m) {
        let p = m.reference_positions()[i as usize];
        m.set_position(i as usize, p + DVec3::X * STRETCH);
    }
    let f1 = settled_reaction(m);
    for i in loaded_end(m) {
        let p = m.reference_positions()[i as usize];
        m.set_position(i as usize, p);
    }
    (f0, (f1 - f0) / STRETCH)
}

/// Cut a slit through the whole depth in the plane y = 0.0113 (between node layers, so edges are split),
/// from x = 2 cm to 4 cm: the middle third, away from both ends.
fn cut_along_the_load(m: &mut MassSpringModel) -> usize {
    let y = 0.0113;
    let blade = |x: f64| BladePose {
        heel: DVec3::new(x, y, -0.005),
        tip: DVec3::new(x, y, SIZE[2] + 0.005),
    };
    let mut cutter = Cutter::new(CutParams::default());
    cutter.begin(m, blade(0.02));
    let mut new_tets = 0;
    for k in 1..=10 {
        new_tets += cutter.advance(m, blade(0.02 + 0.002 * k as f64)).new_tets;
    }
    cutter.end();
    new_tets
}

fn before_and_after(law: StiffnessLaw) -> ((f64, f64), (f64, f64), usize) {
    let mut m = block_model(law);
    let before = tension_and_stiffness(&mut m);
    let added = cut_along_the_load(&mut m);
    let after = tension_and_stiffness(&mut m);
    (before, after, added)
}

#[test]
fn a_cut_region_keeps_the_stiffness_and_tension_of_the_uncut_block() {
    let ((t0, k0), (t1, k1), added) = before_and_after(StiffnessLaw::TetVolume);
    eprintln!(
        "TetVolume: tension {t0:.5} -> {t1:.5} N, stiffness {k0:.3} -> {k1:.3} N/m, {added} tets added"
    );
    assert!(
        added > 50,
        "the cut must subdivide the middle: {added} tets added"
    );
    let dk = (k1 - k0) / k0;
    let dt = (t1 - t0) / t0;
    assert!(
        dk.abs() <= 0.02,
        "stiffness changed by {:+.2} %",
        dk * 100.0
    );
    // Measured: −1.6 % stiffness, −2.5 % tension (the paper's uniform springs: +11 %,
    // +9 %). The tension bound is 3 %: docs/physics-notes.md, "Nakao".
    assert!(dt.abs() <= 0.03, "tension changed by {:+.2} %", dt * 100.0);
}

/// The paper's form (every edge k, the halves of a split edge k each, new edges k): the
/// cut region comes out stiffer and tenser than the uncut one, by more than 5 %.
#[test]
fn the_papers_uniform_springs_change_the_stiffness_of_a_cut_region() {
    let ((t0, k0), (t1, k1), _) = before_and_after(StiffnessLaw::Uniform);
    eprintln!("Uniform: tension {t0:.5} -> {t1:.5} N, stiffness {k0:.3} -> {k1:.3} N/m");
    let dk = (k1 - k0) / k0;
    let dt = (t1 - t0) / t0;
    assert!(
        dk > 0.05 && dt > 0.05,
        "uniform springs kept stiffness ({:+.2} %) and tension ({:+.2} %)",
        dk * 100.0,
        dt * 100.0
    );
}
