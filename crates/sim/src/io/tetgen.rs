//! TetGen `.node` / `.ele` / `.face` files (reader and writer).
//!
//! Indices may start at 0 or 1: the first point index of the `.node` file decides, and the
//! `.ele` and `.face` files use the same numbering. Attributes and boundary markers are
//! ignored. `#` starts a comment.

use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::atomic::write_atomic;
use super::text::{Cursor, Fields, capacity, read_text};
use crate::{MeshError, RawMesh};

/// The points of a `.node` file and the index its numbering starts at.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NodeFile {
    /// Point coordinates, in file order.
    pub positions: Vec<Vec3>,
    /// Index of the first point in the file (0 or 1); `.ele`/`.face` indices count from it.
    pub first_index: u64,
}

/// Read `<stem>.node` and `<stem>.ele` (and `<stem>.face` when it exists) for `path`, which
/// may name either of the first two.
pub fn load_tetgen(path: &Path) -> Result<RawMesh, MeshError> {
    let node_path = path.with_extension("node");
    let ele_path = path.with_extension("ele");
    let face_path = path.with_extension("face");
    let nodes = parse_node(&read_text(&node_path)?, &node_path)?;
    let tets = parse_ele(&read_text(&ele_path)?, &ele_path, &nodes)?;
    let boundary_faces = if face_path.is_file() {
        Some(parse_face(&read_text(&face_path)?, &face_path, &nodes)?)
    } else {
        None
    };
    Ok(RawMesh {
        positions: nodes.positions,
        tets,
        warnings: Vec::new(),
        boundary_faces,
    })
}

/// Parse a `.node` file: header `<points> <dim=3> [<attributes> [<markers>]]`, then
/// `<index> <x> <y> <z> [attributes] [marker]` per point.
pub fn parse_node(text: &str, origin: &Path) -> Result<NodeFile, MeshError> {
    let mut cursor = Cursor::new(text, origin, Some('#'));
    let mut header =
        cursor.expect_line("the .node header \"<points> 3 <attributes> <markers>\"")?;
    let count: u64 = header.next("the number of points")?;
    let dim: u64 = header.next("the dimension")?;
    if dim != 3 {
        return Err(header.error(format!(
            "only 3-dimensional .node files are supported, the header says {dim}"
        )));
    }
    let mut positions = Vec::with_capacity(capacity(count, text));
    let mut first_index = 0;
    for i in 0..count {
        let mut line = cursor.expect_line(format_args!("point {} of {count}", i + 1))?;
        let index: u64 = line.next("a point index")?;
        if i == 0 {
            if index > 1 {
                return Err(line.error(format!(
                    "the first point index must be 0 or 1, found {index}"
                )));
            }
            first_index = index;
        } else if index != first_index + i {
            return Err(line.error(format!(
                "expected point index {}, found {index}",
                first_index + i
            )));
        }
        let x = line.next("an x coordinate")?;
        let y = line.next("a y coordinate")?;
        let z = line.next("a z coordinate")?;
        positions.push(Vec3::new(x, y, z));
    }
    expect_end(&mut cursor, count, "points")?;
    Ok(NodeFile {
        positions,
        first_index,
    })
}

/// Parse an `.ele` file against its `.node` file: header `<tets> <4|10> [<attributes>]`,
/// then `<index> <n1> .. <n4|n10> [attributes]` per tet; 10-node tets keep their corners.
pub fn parse_ele(text: &str, origin: &Path, nodes: &NodeFile) -> Result<Vec<[u32; 4]>, MeshError> {
    let mut cursor = Cursor::new(text, origin, Some('#'));
    let mut header = cursor.expect_line("the .ele header \"<tets> <4|10> <attributes>\"")?;
    let count: u64 = header.next("the number of tets")?;
    let per_tet: u64 = header.next("the number of nodes per tet")?;
    if per_tet != 4 && per_tet != 10 {
        return Err(header.error(format!(
            "tets must have 4 or 10 nodes, the header says {per_tet}"
        )));
    }
    let mut tets = Vec::with_capacity(capacity(count, text));
    for i in 0..count {
        let mut line = cursor.expect_line(format_args!("tet {} of {count}", i + 1))?;
        let _index: u64 = line.next("a tet index")?;
        let mut tet = [0u32; 4];
        for slot in &mut tet {
            *slot = node_index(&mut line, nodes)?;
        }
        tets.push(tet);
    }
    expect_end(&mut cursor, count, "tets")?;
    Ok(tets)
}

/// Parse a `.face` file against its `.node` file: header `<faces> [<markers>]`, then
/// `<index> <a> <b> <c> [marker]` per face.
pub fn parse_face(text: &str, origin: &Path, nodes: &NodeFile) -> Result<Vec<[u32; 3]>, MeshError> {
    let mut cursor = Cursor::new(text, origin, Some('#'));
    let mut header = cursor.expect_line("the .face header \"<faces> <markers>\"")?;
    let count: u64 = header.next("the number of faces")?;
    let mut faces = Vec::with_capacity(capacity(count, text));
    for i in 0..count {
        let mut line = cursor.expect_line(format_args!("face {} of {count}", i + 1))?;
        let _index: u64 = line.next("a face index")?;
        let mut face = [0u32; 3];
        for slot in &mut face {
            *slot = node_index(&mut line, nodes)?;
        }
        faces.push(face);
    }
    expect_end(&mut cursor, count, "faces")?;
    Ok(faces)
}

/// Write `<base>.node` and `<base>.ele` (0-based, no attributes or markers), each atomically.
pub fn write_tetgen(base: &Path, positions: &[Vec3], tets: &[[u32; 4]]) -> Result<(), MeshError> {
    super::check_tets(positions.len(), tets)?;
    let mut node = format!("# written by incise\n{} 3 0 0\n", positions.len());
    for (i, p) in positions.iter().enumerate() {
        let _ = writeln!(node, "{i} {} {} {}", p.x, p.y, p.z);
    }
    let mut ele = format!("# written by incise\n{} 4 0\n", tets.len());
    for (i, t) in tets.iter().enumerate() {
        let _ = writeln!(ele, "{i} {} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    write_atomic(&with_suffix(base, ".node"), node.as_bytes())?;
    write_atomic(&with_suffix(base, ".ele"), ele.as_bytes())
}

/// `base` with `suffix` appended to its file name (`mesh.1` -> `mesh.1.node`).
fn with_suffix(base: &Path, suffix: &str) -> PathBuf {
    let mut name = OsString::from(base.as_os_str());
    name.push(suffix);
    PathBuf::from(name)
}

/// The next field as a node index, converted to 0-based and checked against the points.
fn node_index(line: &mut Fields<'_>, nodes: &NodeFile) -> Result<u32, MeshError> {
    let index: u64 = line.next("a node index")?;
    let count = nodes.positions.len() as u64;
    match index.checked_sub(nodes.first_index) {
        Some(local) if local < count => Ok(local as u32),
        _ if count == 0 => Err(line.error(format!(
            "node index {index} is out of range: the .node file has no points"
        ))),
        _ => Err(line.error(format!(
            "node index {index} is out of range: the .node file numbers its points {}..={}",
            nodes.first_index,
            nodes.first_index + count - 1
        ))),
    }
}

/// After the announced `count` items, only comments and blank lines may follow.
fn expect_end(cursor: &mut Cursor<'_>, count: u64, what: &str) -> Result<(), MeshError> {
    match cursor.next_line() {
        Some(line) => Err(line.error(format!(
            "the header announces {count} {what}, but the file has more lines"
        ))),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::super::format_checks::scratch;
    use super::*;

    const NODE_1BASED: &str = "\
# two tets sharing a face
5 3 0 1
1 0 0 0 7
2 1 0 0 7
3 0 1 0 7
4 0 0 1 7   # apex
5 1 1 1 0
";
    const ELE_1BASED: &str = "2 4 0\n1 1 2 3 4\n2 2 3 4 5\n";

    fn node(text: &str) -> Result<NodeFile, MeshError> {
        parse_node(text, Path::new("m.node"))
    }

    fn ele(text: &str, nodes: &NodeFile) -> Result<Vec<[u32; 4]>, MeshError> {
        parse_ele(text, Path::new("m.ele"), nodes)
    }

    fn err_text<T: std::fmt::Debug>(r: Result<T, MeshError>) -> String {
        r.expect_err("input is malformed").to_string()
    }

    #[test]
    fn one_based_two_tet_mesh_parses_to_zero_based() {
        let nodes = node(NODE_1BASED).expect("valid .node");
        assert_eq!(nodes.first_index, 1);
        assert_eq!(nodes.positions.len(), 5);
        assert_eq!(nodes.positions[4], Vec3::ONE);
        assert_eq!(nodes.positions[3], Vec3::Z);
        let tets = ele(ELE_1BASED, &nodes).expect("valid .ele");
        assert_eq!(tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
    }

    #[test]
    fn zero_based_ten_node_tets_keep_corners() {
        let nodes = node("4 3\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1.5\n").expect("valid");
        assert_eq!(nodes.first_index, 0);
        assert_eq!(nodes.positions[3], Vec3::new(0.0, 0.0, 1.5));
        let tets = ele("1 10 1\n0 3 2 1 0 0 0 0 0 0 0 9.5\n", &nodes).expect("valid");
        assert_eq!(tets, vec![[3, 2, 1, 0]]);
    }

    #[test]
    fn face_file_is_validated_and_zero_based() {
        let nodes = node(NODE_1BASED).expect("valid");
        let faces = parse_face("2 1\n1 1 2 3 -1\n2 2 3 5 0\n", Path::new("m.face"), &nodes);
        assert_eq!(faces.expect("valid"), vec![[0, 1, 2], [1, 2, 4]]);
        let bad = parse_face(
            "2 1\n1 1 2 3 -1\n\n2 2 3 6 0\n",
            Path::new("m.face"),
            &nodes,
        );
        let msg = err_text(bad);
        assert!(
            msg.contains("m.face:4: node index 6 is out of range"),
            "{msg}"
        );
    }

    #[test]
    fn element_index_out_of_range_names_its_line() {
        let nodes = node(NODE_1BASED).expect("valid");
        let msg = err_text(ele("2 4 0\n1 1 2 3 4\n# c\n2 2 3 4 6\n", &nodes));
        assert!(
            msg.contains("m.ele:4: node index 6 is out of range"),
            "{msg}"
        );
        assert!(msg.contains("1..=5"), "{msg}");
        let msg = err_text(ele("1 4 0\n1 0 2 3 4\n", &nodes));
        assert!(
            msg.contains("m.ele:2: node index 0 is out of range"),
            "{msg}"
        );
    }

    #[test]
    fn fewer_points_than_announced_is_an_eof_error_at_last_line() {
        let text = "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\n";
        let msg = err_text(node(text));
        assert!(
            msg.contains("m.node:6: unexpected end of file: expected point 5 of 5"),
            "{msg}"
        );
    }

    #[test]
    fn more_tets_than_announced_is_an_error_at_the_extra_line() {
        let nodes = node(NODE_1BASED).expect("valid");
        let msg = err_text(ele("1 4 0\n1 1 2 3 4\n2 2 3 4 5\n", &nodes));
        assert!(
            msg.contains("m.ele:3: the header announces 1 tets"),
            "{msg}"
        );
    }

    #[test]
    fn non_numeric_and_structural_errors_name_lines() {
        let msg = err_text(node("2 3 0 0\n1 0 0 0\n2 1 zero 0\n"));
        assert!(
            msg.contains("m.node:3: expected a y coordinate, found \"zero\""),
            "{msg}"
        );
        let msg = err_text(node("2 3\n1 0 0 0\n3 1 0 0\n"));
        assert!(
            msg.contains("m.node:3: expected point index 2, found 3"),
            "{msg}"
        );
        let msg = err_text(node("1 2\n1 0 0\n"));
        assert!(msg.contains("m.node:1: only 3-dimensional"), "{msg}");
        let msg = err_text(node("1 3\n5 0 0 0\n"));
        assert!(
            msg.contains("m.node:2: the first point index must be 0 or 1"),
            "{msg}"
        );
        let nodes = node(NODE_1BASED).expect("valid");
        let msg = err_text(ele("1 6 0\n", &nodes));
        assert!(
            msg.contains("m.ele:1: tets must have 4 or 10 nodes"),
            "{msg}"
        );
        let msg = err_text(ele("1 4 0\n1 1 2 3\n", &nodes));
        assert!(
            msg.contains("m.ele:2: expected a node index, found the end"),
            "{msg}"
        );
    }

    #[test]
    fn empty_files_are_errors() {
        let msg = err_text(node(""));
        assert!(msg.contains("m.node:0: the file is empty"), "{msg}");
        let msg = err_text(ele("# only a comment\n", &NodeFile::default()));
        assert!(
            msg.contains("m.ele:1: unexpected end of file: expected the .ele header"),
            "{msg}"
        );
    }

    #[test]
    fn write_then_load_round_trips_through_either_sibling() {
        let dir = scratch("tetgen");
        let positions = vec![
            Vec3::ZERO,
            Vec3::new(0.1, 0.0, 0.0),
            Vec3::new(0.0, 1e-7, 0.0),
            Vec3::new(-3.25, 0.0, 12345.678),
            Vec3::ONE / 3.0,
        ];
        let tets = vec![[0, 1, 2, 3], [1, 2, 3, 4]];
        let base = dir.join("liver.1");
        write_tetgen(&base, &positions, &tets).expect("write");
        for ext in ["liver.1.node", "liver.1.ele"] {
            let raw = super::super::load_mesh(&dir.join(ext)).expect("load");
            assert_eq!(raw.positions, positions);
            assert_eq!(raw.tets, tets);
            assert!(raw.boundary_faces.is_none());
        }
        std::fs::write(dir.join("liver.1.face"), "1 0\n0 0 1 2\n").expect("face");
        let raw = load_tetgen(&dir.join("liver.1.ele")).expect("load with faces");
        assert_eq!(raw.boundary_faces, Some(vec![[0, 1, 2]]));
        let bad = write_tetgen(&base, &positions, &[[0, 1, 2, 5]]);
        assert!(matches!(
            bad,
            Err(MeshError::NodeIndexOutOfRange { node: 5, .. })
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }

    proptest::proptest! {
        #[test]
        fn truncated_or_random_input_never_panics(
            cut in 0usize..200,
            bytes in proptest::collection::vec(proptest::num::u8::ANY, 0..200),
            noise in "[0-9 .#e-]{0,40}(\n[0-9 .#e-]{0,40}){0,8}",
        ) {
            let _ = node(&NODE_1BASED[..cut.min(NODE_1BASED.len())]);
            let random = String::from_utf8_lossy(&bytes);
            let nodes = node(NODE_1BASED).unwrap_or_default();
            for text in [&*random, &noise] {
                let _ = node(text);
                let _ = ele(text, &nodes);
                let _ = parse_face(text, Path::new("m.face"), &nodes);
            }
            let _ = node(&format!("3 3 0 0\n{noise}"));
            let _ = ele(&format!("2 4 0\n{noise}"), &nodes);
            let _ = ele(&ELE_1BASED[..cut.min(ELE_1BASED.len())], &nodes);
        }
    }
}
