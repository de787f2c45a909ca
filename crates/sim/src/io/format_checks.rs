//! What the format tests check alike: a fresh scratch folder, parse errors that name their
//! line, and a mesh read back as it was written.

use std::path::PathBuf;

use glam::Vec3;

use crate::{MeshError, RawMesh};

/// An empty folder `incise-io-<name>-<process id>` in the system's temporary folder.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("incise-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Each `(text, expected)`: `parse(text)` fails with a message that contains `expected`.
pub fn assert_errors(parse: impl Fn(&str) -> Result<RawMesh, MeshError>, cases: &[(String, &str)]) {
    for (text, expected) in cases {
        let msg = parse(text).expect_err("input is malformed").to_string();
        assert!(msg.contains(expected), "expected {expected:?} in: {msg}");
    }
}

/// `raw` holds `positions` (each coordinate to 1e-6 of the point's largest, or of 1),
/// exactly `tets`, and no warnings.
pub fn assert_read_back(raw: &RawMesh, positions: &[Vec3], tets: &[[u32; 4]]) {
    assert_eq!(raw.positions.len(), positions.len());
    for (a, b) in raw.positions.iter().zip(positions) {
        let tolerance = 1e-6 * b.abs().max_element().max(1.0);
        assert!((*a - *b).abs().max_element() <= tolerance, "{a} vs {b}");
    }
    assert_eq!(raw.tets, tets);
    assert!(raw.warnings.is_empty(), "{:?}", raw.warnings);
}

/// `raw` is the two-tet fixture the legacy and XML tests both spell out: five points, tets
/// `0 1 2 3` and `1 2 3 4`, and a triangle skipped with a warning.
pub fn assert_two_tets_and_a_triangle(raw: &RawMesh) {
    assert_eq!(
        raw.positions,
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE]
    );
    assert_eq!(raw.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
    assert_eq!(
        raw.warnings,
        vec!["skipped 1 cell of VTK type 5 (triangle)"]
    );
}
