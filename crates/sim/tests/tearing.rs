//! Validation test 6: a bar pulled at both ends past the threshold tears in two, and the
//! released tets sit where the stress peaked.

mod common;

use glam::{UVec3, Vec3};
use incise_sim::generate::block;
use incise_sim::grab::Grab;
use incise_sim::mesh::topology::{component_labels, connected_components};
use incise_sim::selection::NodeSelection;
use incise_sim::{SolverParams, TetMesh};

const L: f32 = 0.10;

/// A dog-bone tensile specimen: a 10 × 2 × 2 cm bar whose cross-section narrows to 60 % at
/// mid-length (as in a tensile test, so that the stress peak has a known place).
fn dogbone() -> TetMesh {
    let mut raw = block(
        Vec3::new(0.0, -0.01, -0.01),
        Vec3::new(L, 0.02, 0.02),
        UVec3::new(30, 5, 5),
    );
    for p in &mut raw.positions {
        let s = 1.0 - 0.4 * (-((p.x - L / 2.0) / (0.12 * L)).powi(2)).exp();
        p.y *= s;
        p.z *= s;
    }
    TetMesh::from_raw(raw).unwrap().0
}

#[test]
fn bar_pulled_at_both_ends_tears_in_two_at_the_neck() {
    let mesh = dogbone();
    let params = SolverParams {
        gravity: Vec3::ZERO,
        damping: 5.0,
        threads: 1,
        release_threshold: Some(8e3),
        ..SolverParams::default()
    };
    let mut s = common::solver(mesh, common::soft(30e3, 0.4), params);
    let rest = s.mesh().rest_positions.clone();
    for (x, dir) in [(0.004, -1.0f32), (L - 0.004, 1.0)] {
        let nodes = NodeSelection::PlaneSide {
            point: Vec3::new(x, 0.0, 0.0),
            normal: Vec3::X * dir,
        }
        .select(&rest)
        .unwrap();
        s.add_grab(Grab {
            nodes,
            waypoints: vec![Vec3::X * dir * 0.05],
            speed: 0.05,
            start_time: 0.0,
        });
    }
    let centroids: Vec<Vec3> = s
        .mesh()
        .tets
        .iter()
        .map(|t| t.iter().map(|&i| rest[i as usize]).sum::<Vec3>() / 4.0)
        .collect();
    let centroid = |t: usize| centroids[t];
    let mut first_release = None;
    for frame in 0..90 {
        let st = s.step_frame().unwrap();
        if st.released_now > 0 && first_release.is_none() {
            // The stress field the criterion saw is the one of this frame; its peak and the
            // released tets must both be in the neck.
            let vm = s.von_mises();
            let peak = (0..vm.len())
                .max_by(|&a, &b| vm[a].total_cmp(&vm[b]))
                .unwrap();
            first_release = Some((frame, peak));
        }
        if connected_components(s.mesh(), |t| s.cut().is_live(t)) >= 2 {
            break;
        }
    }
    let (frame, peak) = first_release.expect("the bar never tore");
    assert!(
        (centroid(peak).x - L / 2.0).abs() < 0.2 * L,
        "stress peaked at x = {}",
        centroid(peak).x
    );
    let released: Vec<usize> = (0..s.mesh().tet_count())
        .filter(|&t| !s.cut().is_live(t))
        .collect();
    assert!(!released.is_empty());
    let in_neck = released
        .iter()
        .filter(|&&t| (centroid(t).x - L / 2.0).abs() < 0.2 * L)
        .count();
    assert!(
        in_neck as f32 >= 0.9 * released.len() as f32,
        "only {in_neck} of {} released tets are in the neck (first release at frame {frame})",
        released.len()
    );
    let (labels, n) = component_labels(s.mesh(), |t| s.cut().is_live(t));
    assert_eq!(n, 2, "the bar should separate into exactly two pieces");
    // The two pieces are the left and the right half (away from the neck).
    let left_label = labels[(0..s.mesh().tet_count())
        .find(|&u| centroid(u).x < 0.01)
        .unwrap()];
    for (t, &label) in labels.iter().enumerate() {
        let x = centroid(t).x;
        if label != u32::MAX && (x - L / 2.0).abs() > 0.2 * L {
            assert_eq!(
                label == left_label,
                x < L / 2.0,
                "tet {t} at x = {x} is on the wrong piece"
            );
        }
    }
}
