//! The solver's box distance (`incise_sim::contact::box_distance`, mirrored in the WGSL
//! contact shader) against parry3d's, and `Tool::body_distance` against the solver's
//! distance of the placed body.

use std::path::Path;

use glam::{Quat, Vec3};
use incise_scalpel::load_tool;
use incise_sim::contact::{ContactTool, PlacedTool, ToolPose, box_distance};
use parry3d::math::Vector;
use parry3d::query::PointQuery;
use parry3d::shape::Cuboid;
use proptest::prelude::*;

fn parry(v: Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

fn vec3(range: std::ops::Range<f32>) -> impl Strategy<Value = Vec3> {
    (range.clone(), range.clone(), range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

proptest! {
    #[test]
    fn box_distance_matches_parry(
        h in vec3(0.01..2.0),
        p in vec3(-4.0..4.0),
    ) {
        let ours = box_distance(p, h);
        let cuboid = Cuboid::new(parry(h));
        let theirs = cuboid.distance_to_local_point(parry(p), false);
        if cuboid.contains_local_point(parry(p)) {
            // Inside: both negative (parry: depth to the nearest face, as ours).
            prop_assert!(ours <= 0.0, "ours {ours} at {p} in {h}");
            prop_assert!(theirs <= 0.0);
            prop_assert!((ours - theirs).abs() <= 1e-5, "ours {ours}, parry {theirs}");
        } else {
            prop_assert!(ours >= -1e-6, "ours {ours} at {p} outside {h}");
            prop_assert!((ours - theirs).abs() <= 1e-5 * (1.0 + theirs), "ours {ours}, parry {theirs}");
        }
    }

    #[test]
    fn body_distance_matches_the_solver_outside_and_in_sign(
        p in vec3(-0.02..0.17),
        axis in vec3(-1.0..1.0),
        angle in -3.0f32..3.0,
        offset in vec3(-0.05..0.05),
    ) {
        let tool = load_tool(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/tools/scalpel_10.ron")).unwrap();
        let body = ContactTool { spheres: vec![], boxes: tool.body().to_vec(), friction: 0.0 };
        // The solver evaluates boxes in the world: place the tool anywhere, map the point.
        let rotation = Quat::from_axis_angle(axis.try_normalize().unwrap_or(Vec3::X), angle);
        let pose = ToolPose::new(offset, rotation);
        let placed = PlacedTool::new(&body, &pose);
        let solver = placed.distance(pose.transform_point(p));
        let ours = tool.body_distance(p);
        let inside = tool.body_shape().contains_local_point(parry(p));
        // (Within rounding of a face the two may disagree on the side.)
        if solver.abs() > 1e-6 {
            prop_assert_eq!(inside, solver < 0.0, "p {}: solver {}, parry {}", p, solver, ours);
        }
        if ours.abs() > 1e-6 {
            prop_assert_eq!(inside, ours < 0.0, "p {}: ours {}", p, ours);
        }
        // Inside and out, the least of the boxes' signed distances (the solver's union).
        prop_assert!((ours - solver).abs() <= 2e-6, "p {}: solver {}, parry {}", p, solver, ours);
    }
}

/// A point inside the handle and 18 µm outside the blade flat that overlaps it (the
/// input CI's proptest found): inside the body, at the handle's depth.
#[test]
fn inside_the_handle_beside_the_blade_flat_is_inside() {
    let tool =
        load_tool(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/tools/scalpel_10.ron"))
            .unwrap();
    let p = Vec3::new(0.031_380_98, -0.000_218_135_39, 0.0);
    assert!(tool.body_shape().contains_local_point(parry(p)));
    let depth = tool.body_distance(p);
    // Handle: x from 30 mm, y within 1.4 mm: the nearest face is y = -1.4 mm.
    assert!(
        (depth + (0.0014 - 0.000_218_135_39)).abs() < 1e-6,
        "{depth}"
    );
}

#[test]
fn rotated_box_agrees_with_parry_pose() {
    use parry3d::math::{Pose, Rotation};
    let h = Vec3::new(0.3, 0.1, 0.2);
    let q = Quat::from_rotation_y(0.6) * Quat::from_rotation_x(-0.3);
    let c = Vec3::new(0.5, -0.2, 0.1);
    let pose = Pose::from_parts(parry(c), Rotation::from_xyzw(q.x, q.y, q.z, q.w));
    let cuboid = Cuboid::new(parry(h));
    for i in 0..200 {
        let f = i as f32;
        let p = Vec3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 0.8;
        let local = q.inverse() * (p - c);
        let ours = box_distance(local, h);
        let theirs = cuboid.distance_to_point(&pose, parry(p), false);
        assert!((ours - theirs).abs() < 1e-5, "{p}: {ours} vs {theirs}");
    }
}
