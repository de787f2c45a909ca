//! The shipped tool files, the sphere rules, the render mesh and bad tool files.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use incise_scalpel::{FileError, SpherePlacement, load_tool, parse_tool};
use incise_sim::ron_file::SyntaxError;

fn tools_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/tools")
}

fn shipped(name: &str) -> (PathBuf, String) {
    let path = tools_dir().join(format!("{name}.ron"));
    let text = std::fs::read_to_string(&path).expect("read shipped tool file");
    (path, text)
}

/// Distance from `p` to the polyline, in the x–z plane.
fn polyline_distance(p: Vec2, line: &[Vec2]) -> f32 {
    line.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            (p - (a + (b - a) * t)).length()
        })
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn both_shipped_tools_load() {
    for name in ["scalpel_10", "scalpel_11"] {
        let tool = load_tool(&tools_dir().join(format!("{name}.ron")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(tool.name(), name);
        assert!(tool.source().contains("nominal"), "{}", tool.source());
        assert!((tool.thickness() - 0.4e-3).abs() < 1e-9);
        assert!((tool.friction() - 0.15).abs() < 1e-9);
        assert_eq!(tool.body().len(), 2);
        assert!(tool.is_sharp());
        // The edge starts at the tip, the tool-frame origin.
        assert_eq!(tool.edge()[0], Vec2::ZERO);
        let contact = tool.contact_tool(2e-3);
        contact.validate().expect("solver accepts the tool");
        assert!(contact.has_cutting_edge());
    }
}

#[test]
fn from_tissue_rule_sizes_and_counts_spheres() {
    let (path, text) = shipped("scalpel_10");
    let tool = parse_tool(&text, &path).unwrap();
    assert!(matches!(
        tool.placement(),
        SpherePlacement::FromTissue {
            radius_factor: 0.5,
            spacing_factor: 1.5
        }
    ));
    for mean_edge in [1e-3f32, 2e-3, 3.7e-3] {
        let contact = tool.contact_tool(mean_edge);
        let r = 0.5 * mean_edge;
        let spacing = 1.5 * r;
        let expected = (tool.edge_length() / spacing).ceil() as usize + 1;
        assert_eq!(contact.spheres.len(), expected, "mean edge {mean_edge}");
        for s in &contact.spheres {
            assert_eq!(s.radius, r);
            assert!(s.cutting);
            assert_eq!(s.centre.y, 0.0);
            // Tangent to the edge from inside: the edge passes at most r from the centre
            // (≥ 0.9 r at the polyline's corners, where the normal is blended).
            let d = polyline_distance(Vec2::new(s.centre.x, s.centre.z), tool.edge());
            assert!(d <= r * (1.0 + 1e-4) && d >= 0.9 * r, "d = {d}, r = {r}");
        }
        // First sphere touches the tip, last the heel.
        let first = contact.spheres[0].centre;
        let last = contact.spheres[contact.spheres.len() - 1].centre;
        assert!((Vec2::new(first.x, first.z).length() - r).abs() < 1e-6);
        let heel = *tool.edge().last().unwrap();
        assert!((Vec2::new(last.x, last.z) - heel).length() - r < 1e-6);
        // Spheres lie above the edge (inside the blade side): the belly's spheres have a
        // centre higher than the edge point below them.
        let mid = contact.spheres[contact.spheres.len() / 2].centre;
        assert!(mid.z > -5.0e-3 + 0.5 * r);
    }
}

#[test]
fn fixed_rule_ignores_the_tissue_and_spaces_evenly() {
    let (path, text) = shipped("scalpel_11");
    let tool = parse_tool(&text, &path).unwrap();
    let a = tool.contact_tool(1e-3);
    let b = tool.contact_tool(5e-3);
    assert_eq!(a, b);
    assert_eq!(a.spheres.len(), 17);
    // Straight 25 mm edge: 16 gaps of 25/16 mm between centres.
    for w in a.spheres.windows(2) {
        assert!(((w[1].centre - w[0].centre).length() - 25e-3 / 16.0).abs() < 1e-6);
        assert_eq!(w[0].radius, 0.75e-3);
    }
    // Inward normal of the edge (24, −7)/25 rotated +90°: (7, 24)/25, up and back.
    let c0 = a.spheres[0].centre;
    assert!((c0 - Vec3::new(7.0, 0.0, 24.0) / 25.0 * 0.75e-3).length() < 1e-8);
}

#[test]
fn dull_tool_edge_pushes_but_never_cuts() {
    let tool = load_tool(&tools_dir().join("scalpel_10.ron")).unwrap();
    let dull = tool.dull();
    assert!(!dull.is_sharp());
    let c = dull.contact_tool(2e-3);
    assert!(!c.has_cutting_edge());
    assert_eq!(c.spheres.len(), tool.contact_tool(2e-3).spheres.len());
    assert_eq!(c.boxes, tool.contact_tool(2e-3).boxes);
    assert_eq!(c, tool.contact_tool(2e-3).dulled());
}

#[test]
fn render_mesh_is_closed_and_outward() {
    for name in ["scalpel_10", "scalpel_11"] {
        let tool = load_tool(&tools_dir().join(format!("{name}.ron"))).unwrap();
        let (v, tris) = tool.render_mesh();
        // Every directed edge once, and its reverse once: closed, consistently wound.
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "{name}: edge {a}->{b} used {n} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "{name}: {a}->{b} open");
        }
        // Positive volume = blade area × thickness + handle box.
        let volume: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| v[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let area: f64 = {
            let o = tool.outline();
            0.5 * (0..o.len())
                .map(|i| o[i].as_dvec2().perp_dot(o[(i + 1) % o.len()].as_dvec2()))
                .sum::<f64>()
                .abs()
        };
        let h = tool.handle();
        let expected = area * tool.thickness() as f64 + (h.length * h.width * h.thickness) as f64;
        assert!(
            (volume - expected).abs() < 1e-6 * expected,
            "{name}: volume {volume} vs {expected}"
        );
    }
}

fn value_error(text: &str) -> (usize, String, String) {
    match parse_tool(text, Path::new("bad.ron")).unwrap_err() {
        FileError::Value {
            line, field, msg, ..
        } => (line, field, msg),
        other => panic!("expected a value error, got {other}"),
    }
}

#[test]
fn zero_spheres_and_negative_radius_name_the_field_and_line() {
    let (_, text) = shipped("scalpel_11");
    let line_of = |text: &str, pat: &str| {
        1 + text
            .lines()
            .position(|l| l.contains(pat) && !l.trim_start().starts_with("//"))
            .unwrap()
    };
    let bad = text.replace("Fixed(count: 17,", "Fixed(count: 0,");
    let (line, field, _) = value_error(&bad);
    assert_eq!(field, "spheres.count");
    assert_eq!(line, line_of(&bad, "spheres: Fixed"));
    let bad = text.replace("radius: 0.75)", "radius: -0.75)");
    let (line, field, msg) = value_error(&bad);
    assert_eq!(field, "spheres.radius");
    assert_eq!(line, line_of(&bad, "spheres: Fixed"));
    assert!(msg.contains("-0.75"), "{msg}");
    let e = parse_tool(&bad, Path::new("bad.ron"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("bad.ron:{line}: spheres.radius: ")),
        "{e}"
    );
    let (_, text) = shipped("scalpel_10");
    let bad = text.replace("radius_factor: 0.5", "radius_factor: 0.0");
    assert_eq!(value_error(&bad).1, "spheres.radius_factor");
}

#[test]
fn other_bad_values_name_their_fields() {
    let (_, text) = shipped("scalpel_11");
    let cases = [
        ("thickness: 0.4", "thickness: -0.4", "thickness"),
        ("thickness: 0.4", "thickness: inf", "thickness"),
        ("edge: [(0.0, 0.0), (24.0, -7.0)]", "edge: []", "edge"),
        (
            "edge: [(0.0, 0.0), (24.0, -7.0)]",
            "edge: [(0.0, 0.0), (0.0, 0.0)]",
            "edge[1]",
        ),
        ("friction: 0.15", "friction: -0.1", "friction"),
        ("(28.0, -6.0),", "(28.0, -6.0), (20.0, 5.0),", "outline"),
        (
            "half_extents: (15.0, 0.2, 1.0)",
            "half_extents: (15.0, 0.0, 1.0)",
            "body[0].half_extents.y",
        ),
        (
            "half_extents: (15.0, 0.2, 1.0)",
            "half_extents: (15.0, 0.2, 1.0), rotation: (0.0, 0.0, 0.0, 1.2)",
            "body[0].rotation",
        ),
        ("length: 125.0", "length: NaN", "handle.length"),
    ];
    for (from, to, field) in cases {
        assert!(text.contains(from), "{from}");
        let bad = text.replacen(from, to, 1);
        let (line, got, msg) = value_error(&bad);
        assert_eq!(got, field, "{to}: {msg}");
        assert!(line > 0, "{field}: line not found");
    }
    let bad = text.replace(
        "half_extents: (15.0, 0.2, 1.0)",
        "half_extents: (15.0, 0.2, 1.0), rotation: (0.0, 0.0, 0.0, 1.2)",
    );
    let (_, _, msg) = value_error(&bad);
    assert_eq!(msg, "not a unit quaternion (length 1.2)");
}

#[test]
fn malformed_ron_gives_line_and_column() {
    let (_, text) = shipped("scalpel_11");
    // Drop the comma after the thickness: the next field is unexpected there.
    let bad = text.replace("thickness: 0.4,", "thickness: 0.4");
    let e = parse_tool(&bad, Path::new("bad.ron")).unwrap_err();
    let line = 1 + bad.lines().position(|l| l.contains("edge: [")).unwrap();
    match &e {
        FileError::Syntax(SyntaxError { line: l, col, .. }) => {
            assert_eq!(*l, line, "{e}");
            assert!(*col > 1, "{e}");
        }
        other => panic!("expected a syntax error, got {other}"),
    }
    assert!(
        e.to_string().starts_with(&format!("bad.ron:{line}:")),
        "{e}"
    );
    // An unknown field is named.
    let bad = text.replace("thickness: 0.4,", "thickness: 0.4,\n    thicknes: 0.4,");
    let e = parse_tool(&bad, Path::new("bad.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("thicknes"), "{e}");
    // A missing file names the file.
    let e = load_tool(Path::new("/no/such/tool.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/no/such/tool.ron"), "{e}");
}
