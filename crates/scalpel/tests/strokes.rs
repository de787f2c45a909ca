//! Strokes: the file format, interpolation through the keys, save/load, recording and
//! the scripted incision.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use incise_scalpel::{
    FileError, Incision, PoseKey, Stroke, StrokeRecorder, load_stroke, parse_stroke,
};
use incise_sim::contact::ToolPose;
use incise_sim::ron_file::SyntaxError;
use proptest::prelude::*;

const GOOD: &str = "(
    poses: [
        (t: 0.0, position: (0.0, 0.0, 0.02), rotation: (0.0, 0.0, 0.0, 1.0)),
        (t: 0.25, position: (0.001, 0.0, -0.003), rotation: (0.0, 0.0, 0.0, 1.0)),
        (t: 0.4, position: (0.03, 0.005, -0.004), rotation: (0.0, 0.0, 0.38268343, 0.9238795)),
        (t: 1.1, position: (0.06, 0.0, -0.002), rotation: (0.0, 0.0, -0.38268343, 0.9238795)),
        (t: 1.3, position: (0.065, 0.0, 0.02), rotation: (0.0, 0.0, 0.0, 1.0)),
    ],
)";

fn good() -> Stroke {
    parse_stroke(GOOD, Path::new("good.ron")).expect("good stroke")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "incise-scalpel-strokes-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

#[test]
fn passes_through_every_key_bit_exactly_and_holds_the_ends() {
    let s = good();
    for k in s.keys() {
        let p = s.pose_at(k.t);
        assert_eq!(p.position, k.position);
        assert_eq!(p.rotation, k.rotation);
        assert_eq!(
            p.position.to_array().map(f32::to_bits),
            k.position.to_array().map(f32::to_bits)
        );
    }
    let first = s.keys()[0];
    let last = *s.keys().last().unwrap();
    assert_eq!(s.pose_at(-5.0), first.pose());
    assert_eq!(s.pose_at(f64::NEG_INFINITY), first.pose());
    assert_eq!(s.pose_at(f64::NAN), first.pose());
    assert_eq!(s.pose_at(1.3000001), last.pose());
    assert_eq!(s.pose_at(f64::INFINITY), last.pose());
    assert_eq!(s.duration(), 1.3);
}

#[test]
fn position_is_c1_between_and_across_keys() {
    let s = good();
    let pos = |t: f64| s.pose_at(t).position.as_dvec3();
    let h = 1e-4;
    // Across interior keys: left and right velocities agree.
    for k in &s.keys()[1..s.keys().len() - 1] {
        let left = (pos(k.t) - pos(k.t - h)) / h;
        let right = (pos(k.t + h) - pos(k.t)) / h;
        let scale = left.length().max(right.length()).max(1e-3);
        assert!(
            (left - right).length() < 0.02 * scale,
            "kink at t = {}: {left} vs {right}",
            k.t
        );
    }
    // Inside segments: velocity changes smoothly (no jumps between fine steps).
    let mut t = 0.001;
    let mut prev = (pos(t + h) - pos(t)) / h;
    while t + 0.001 + h < 1.3 {
        t += 0.001;
        let v = (pos(t + h) - pos(t)) / h;
        assert!(
            (v - prev).length() < 0.02,
            "velocity jump at {t}: {prev} -> {v}"
        );
        prev = v;
    }
}

#[test]
fn rotation_is_unit_and_takes_the_short_way() {
    let s = good();
    for i in 0..=1300 {
        let q = s.pose_at(i as f64 * 1e-3).rotation;
        assert!((q.length() - 1.0).abs() < 1e-6, "{q}");
    }
    // Halfway between +45° and −45° about z: identity.
    let mid = s.pose_at(0.75).rotation;
    assert!(mid.dot(Quat::IDENTITY).abs() > 1.0 - 1e-6, "{mid}");
    // A key stored with the opposite sign does not make the tool spin the long way.
    let keys = vec![
        PoseKey {
            t: 0.0,
            position: Vec3::ZERO,
            rotation: Quat::from_rotation_x(0.2),
        },
        PoseKey {
            t: 1.0,
            position: Vec3::ZERO,
            rotation: -Quat::from_rotation_x(0.4),
        },
    ];
    let q = Stroke::new(keys).unwrap().pose_at(0.5).rotation;
    assert!(q.dot(Quat::from_rotation_x(0.3)).abs() > 1.0 - 1e-6, "{q}");
}

#[test]
fn save_and_load_round_trip_bit_for_bit() {
    let awkward = [
        0.1f32,
        1.0 / 3.0,
        -2.5e-7,
        1.0e-38,
        3.0e38,
        -0.0,
        0.007_812_5,
        16_777_217.0,
    ];
    let mut keys = Vec::new();
    for (i, &a) in awkward.iter().enumerate() {
        let rotation = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.1 + i as f32);
        keys.push(PoseKey {
            t: i as f64 * 0.1 + 1.0 / 7.0,
            position: Vec3::new(a, -a * 0.5, i as f32 * std::f32::consts::PI),
            rotation,
        });
    }
    let stroke = Stroke::new(keys).unwrap();
    let dir = scratch("roundtrip");
    let path = dir.join("stroke.ron");
    stroke.save(&path).unwrap();
    assert!(!dir.join("stroke.ron.tmp").exists());
    let back = load_stroke(&path).unwrap();
    assert_eq!(back.keys().len(), stroke.keys().len());
    for (a, b) in stroke.keys().iter().zip(back.keys()) {
        assert_eq!(a.t.to_bits(), b.t.to_bits());
        assert_eq!(
            a.position.to_array().map(f32::to_bits),
            b.position.to_array().map(f32::to_bits)
        );
        assert_eq!(
            a.rotation.to_array().map(f32::to_bits),
            b.rotation.to_array().map(f32::to_bits)
        );
    }
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("poses:") && text.contains("rotation:"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn value_error(text: &str) -> (usize, String, String, String) {
    let e = parse_stroke(text, Path::new("s.ron")).unwrap_err();
    let shown = e.to_string();
    match e {
        FileError::Value {
            line, field, msg, ..
        } => (line, field, msg, shown),
        other => panic!("expected a value error, got {other}"),
    }
}

#[test]
fn bad_strokes_name_the_pose_and_field() {
    // Times not increasing: poses[3].t (line 6).
    let bad = GOOD.replace("(t: 1.1,", "(t: 0.4,");
    let (line, field, msg, shown) = value_error(&bad);
    assert_eq!(field, "poses[3].t");
    assert_eq!(line, 6);
    assert!(msg.contains("poses[2].t"), "{msg}");
    assert!(shown.starts_with("s.ron:6: poses[3].t: "), "{shown}");
    // Non-unit quaternion: poses[1].rotation, with its length.
    let bad = GOOD.replace(
        "(t: 0.25, position: (0.001, 0.0, -0.003), rotation: (0.0, 0.0, 0.0, 1.0))",
        "(t: 0.25, position: (0.001, 0.0, -0.003), rotation: (0.0, 0.0, 0.0, 1.2))",
    );
    let (line, field, msg, _) = value_error(&bad);
    assert_eq!((line, field.as_str()), (4, "poses[1].rotation"));
    assert_eq!(msg, "not a unit quaternion (length 1.2)");
    // Non-finite position and time.
    let bad = GOOD.replace("(0.03, 0.005, -0.004)", "(0.03, inf, -0.004)");
    assert_eq!(value_error(&bad).1, "poses[2].position");
    let bad = GOOD.replace("(t: 1.3,", "(t: NaN,");
    assert_eq!(value_error(&bad).1, "poses[4].t");
    // Fewer than two poses.
    let one = "(poses: [(t: 0.0, position: (0.0, 0.0, 0.0), rotation: (0.0, 0.0, 0.0, 1.0))])";
    let (line, field, msg, _) = value_error(one);
    assert_eq!((line, field.as_str()), (1, "poses"));
    assert!(msg.contains("at least 2"), "{msg}");
}

#[test]
fn malformed_stroke_gives_line_and_column() {
    let bad = GOOD.replace(
        "(t: 0.4, position: (0.03, 0.005, -0.004)",
        "(t: 0.4 position: (0.03, 0.005, -0.004)",
    );
    match parse_stroke(&bad, Path::new("s.ron")).unwrap_err() {
        FileError::Syntax(SyntaxError { line, col, .. }) => {
            assert_eq!(line, 5);
            assert!(col > 10);
        }
        other => panic!("expected a syntax error, got {other}"),
    }
    let bad = GOOD.replace("position: (0.0, 0.0, 0.02)", "positon: (0.0, 0.0, 0.02)");
    let e = parse_stroke(&bad, Path::new("s.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("s.ron:3:") && e.contains("positon"), "{e}");
}

/// A recorded hand that let the trigger go between samples: the finished stroke is
/// lifted there, engaged at each sample exactly as recorded (and a hair either side of
/// its time), and keeps its lifted spans through a file; a stroke file without them is
/// engaged from its first key to its last.
#[test]
fn a_recorded_stroke_is_lifted_where_the_hand_did_not_engage() {
    let flags = [false, true, true, false, false, true, false];
    let mut r = StrokeRecorder::new();
    for (i, &engaged) in flags.iter().enumerate() {
        let pose = ToolPose::new(Vec3::X * i as f32 * 0.01, Quat::IDENTITY);
        r.push_engaged(0.1 * i as f64, pose, engaged).unwrap();
    }
    let s = r.finish().unwrap();
    let check = |s: &Stroke| {
        for (k, &engaged) in s.keys().iter().zip(&flags) {
            for t in [k.t, k.t - 1e-9, k.t + 1e-9] {
                if t >= s.start_time() && t <= s.end_time() {
                    assert_eq!(s.engaged_at(t), engaged, "at {t} s: {:?}", s.lifted());
                }
            }
        }
    };
    check(&s);
    let dir = scratch("lifted");
    let path = dir.join("lifted.ron");
    s.save(&path).unwrap();
    let loaded = load_stroke(&path).unwrap();
    assert_eq!(loaded, s);
    check(&loaded);
    let plain = good();
    assert!(plain.lifted().is_empty());
    assert!(plain.engaged_at(0.0) && plain.engaged_at(1.3) && !plain.engaged_at(1.31));
    assert!(
        std::fs::read_to_string(&path)
            .unwrap()
            .contains("lifted: [")
    );
    // Spans out of order are refused, naming the span and its line.
    let bad = GOOD.replace(
        "    ],\n)",
        "    ],\n    lifted: [(0.5, 0.6), (0.55, 0.7)],\n)",
    );
    let (line, field, _, _) = value_error(&bad);
    assert_eq!((line, field.as_str()), (9, "lifted[1]"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn recorder_refuses_bad_samples_and_finishes() {
    let mut r = StrokeRecorder::new();
    assert!(r.is_empty());
    r.push(0.0, ToolPose::new(Vec3::ZERO, Quat::IDENTITY))
        .unwrap();
    let e = r.push(0.0, ToolPose::default()).unwrap_err();
    assert_eq!(e.field, "poses[1].t");
    let e = r
        .push(0.1, ToolPose::new(Vec3::NAN, Quat::IDENTITY))
        .unwrap_err();
    assert_eq!(e.field, "poses[1].position");
    // Slightly drifted rotations are normalised.
    r.push(
        0.1,
        ToolPose::new(Vec3::X, Quat::from_xyzw(0.0, 0.0, 0.0, 1.01)),
    )
    .unwrap();
    assert_eq!(r.len(), 2);
    let s = r.finish().unwrap();
    assert_eq!(s.keys()[1].rotation, Quat::IDENTITY);
    assert!(StrokeRecorder::new().finish().is_err());
}

#[test]
fn incision_goes_down_along_and_up_at_speed() {
    let inc = Incision {
        start: Vec3::new(-0.03, 0.0, 0.0),
        end: Vec3::new(0.03, 0.0, 0.0),
        depth: 0.004,
        rotation: Quat::from_rotation_x(0.1),
        approach: 0.01,
        speed: 0.05,
        dt_key: 0.02,
        up: Vec3::Z,
    };
    let s = Stroke::incision(&inc).unwrap();
    let c = inc.corners();
    assert_eq!(s.keys()[0].position, c[0]);
    assert_eq!(s.keys().last().unwrap().position, c[3]);
    for corner in c {
        assert!(s.keys().iter().any(|k| k.position == corner), "{corner}");
    }
    let length = 2.0 * (0.004 + 0.01) + 0.06;
    assert!(
        (s.duration() - length / 0.05).abs() < 1e-6,
        "{}",
        s.duration()
    );
    assert!(s.keys().iter().all(|k| k.rotation == inc.rotation));
    // Mid-incision the tip is at depth, moving along +x at the speed.
    let t = s.duration() * 0.5;
    let p = s.pose_at(t).position;
    assert!((p.z + 0.004).abs() < 1e-6, "{p}");
    let v = (s.pose_at(t + 1e-3).position - s.pose_at(t - 1e-3).position) / 2e-3;
    assert!((v - Vec3::new(0.05, 0.0, 0.0)).length() < 1e-3, "{v}");
    // Corner rounding stays within the documented 4/27 of the key spacing.
    let spacing = 0.05 * 0.02;
    for i in 0..=2000 {
        let z = s.pose_at(s.duration() * i as f64 / 2000.0).position.z;
        assert!(z >= -0.004 - 4.0 / 27.0 * spacing, "z = {z}");
    }
    let bad = Incision { speed: 0.0, ..inc };
    assert_eq!(Stroke::incision(&bad).unwrap_err().field, "speed");
}

fn unit_quat() -> impl Strategy<Value = Quat> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-zero", |(x, y, z, w)| {
            x * x + y * y + z * z + w * w > 1e-2
        })
        .prop_map(|(x, y, z, w)| Quat::from_xyzw(x, y, z, w).normalize())
}

fn stroke_keys() -> impl Strategy<Value = Vec<PoseKey>> {
    prop::collection::vec(
        (
            1e-6f64..10.0,
            (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
            unit_quat(),
        ),
        2..12,
    )
    .prop_map(|raw| {
        let mut t = -1.0;
        raw.into_iter()
            .map(|(dt, (x, y, z), rotation)| {
                t += dt;
                PoseKey {
                    t,
                    position: Vec3::new(x, y, z),
                    rotation,
                }
            })
            .collect()
    })
}

proptest! {
    #[test]
    fn random_valid_strokes_give_finite_unit_poses(
        keys in stroke_keys(),
        samples in prop::collection::vec(0.0f64..1.0, 1..40),
    ) {
        let s = Stroke::new(keys).unwrap();
        let (a, b) = (s.start_time() - 1.0, s.end_time() + 1.0);
        for u in samples {
            let p = s.pose_at(a + (b - a) * u);
            prop_assert!(p.position.is_finite(), "{}", p.position);
            prop_assert!(p.rotation.is_finite());
            prop_assert!((p.rotation.length() - 1.0).abs() < 1e-5);
        }
        for k in s.keys() {
            prop_assert_eq!(s.pose_at(k.t), k.pose());
        }
    }
}
