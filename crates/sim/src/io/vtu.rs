//! VTK XML unstructured grids (`.vtu`, ASCII data): snapshot writer and tetra reader.
//!
//! The writer emits Float32 points, Int64 connectivity/offsets, UInt8 cell types (10) and
//! the frame's point and cell fields, readable by ParaView and meshio. The reader takes
//! ASCII `UnstructuredGrid` files (one or more pieces), keeps tetra cells and ignores data
//! arrays; binary or appended data is refused with a clear error.

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use super::atomic::write_atomic;
use super::text::{Cursor, capacity, quote};
use super::vtk_cells::{CellList, VTK_TETRA, tets_from_cells};
use super::xml::{Scanner, Tag, TagKind, escape_attr};
use crate::{MeshError, RawMesh};

/// One simulation snapshot to write: geometry plus named per-cell and per-point fields.
#[derive(Debug, Clone, Default)]
pub struct VtuFrame<'a> {
    /// Node positions.
    pub positions: &'a [Vec3],
    /// Tets as 0-based node indices.
    pub tets: &'a [[u32; 4]],
    /// Per-tet scalar fields (name, one value per tet), e.g. von Mises stress.
    pub cell_scalars: Vec<(&'a str, &'a [f32])>,
    /// Per-node vector fields (name, one value per node), e.g. velocity.
    pub point_vectors: Vec<(&'a str, &'a [Vec3])>,
    /// Per-node scalar fields (name, one value per node).
    pub point_scalars: Vec<(&'a str, &'a [f32])>,
}

impl<'a> VtuFrame<'a> {
    /// A frame with geometry only; push fields onto the public vectors.
    pub fn new(positions: &'a [Vec3], tets: &'a [[u32; 4]]) -> Self {
        Self {
            positions,
            tets,
            ..Self::default()
        }
    }
}

/// Write `frame` as an ASCII `.vtu` file, atomically (via `<path>.tmp` and a rename).
///
/// Fails, naming the field, when a field's length differs from the node or tet count or
/// a name is empty or repeated; fails when a tet references a missing node.
pub fn write_vtu(path: &Path, frame: &VtuFrame) -> Result<(), MeshError> {
    check_frame(path, frame)?;
    let (n, m) = (frame.positions.len(), frame.tets.len());
    let mut s = String::with_capacity(48 * n + 64 * m + 1024);
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    s.push_str("  <UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{m}\">"
    );
    if !frame.point_scalars.is_empty() || !frame.point_vectors.is_empty() {
        s.push_str("      <PointData>\n");
        for (name, values) in &frame.point_scalars {
            array(&mut s, "Float32", Some(name), 1, values.iter(), |s, v| {
                let _ = write!(s, "{v}");
            });
        }
        for (name, values) in &frame.point_vectors {
            array(&mut s, "Float32", Some(name), 3, values.iter(), vec3);
        }
        s.push_str("      </PointData>\n");
    }
    if !frame.cell_scalars.is_empty() {
        s.push_str("      <CellData>\n");
        for (name, values) in &frame.cell_scalars {
            array(&mut s, "Float32", Some(name), 1, values.iter(), |s, v| {
                let _ = write!(s, "{v}");
            });
        }
        s.push_str("      </CellData>\n");
    }
    s.push_str("      <Points>\n");
    array(&mut s, "Float32", None, 3, frame.positions.iter(), vec3);
    s.push_str("      </Points>\n      <Cells>\n");
    array(
        &mut s,
        "Int64",
        Some("connectivity"),
        1,
        frame.tets.iter(),
        |s, t| {
            let _ = write!(s, "{} {} {} {}", t[0], t[1], t[2], t[3]);
        },
    );
    array(&mut s, "Int64", Some("offsets"), 1, 1..=m, |s, k| {
        let _ = write!(s, "{}", 4 * k);
    });
    array(&mut s, "UInt8", Some("types"), 1, 0..m, |s, _| {
        let _ = write!(s, "{VTK_TETRA}");
    });
    s.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    write_atomic(path, s.as_bytes())
}

/// Parse an ASCII `.vtu` unstructured grid into its points and tetra cells.
pub fn parse_vtu(text: &str, origin: &Path) -> Result<RawMesh, MeshError> {
    let mut sc = Scanner::new(text, origin);
    let mut raw = RawMesh::default();
    let mut is_grid = false;
    let mut piece: Option<Piece> = None;
    let mut section = Section::Other;
    let mut pieces = 0usize;
    while let Some(tag) = sc.next_tag()? {
        let line = sc.line_at(tag.start);
        match (tag.name, tag.kind) {
            ("VTKFile", TagKind::Start) => {
                let ty = tag.attr("type").unwrap_or("");
                if ty != "UnstructuredGrid" {
                    return Err(sc.error(
                        line,
                        format!(
                            "only VTKFile type=\"UnstructuredGrid\" is supported, found {}",
                            quote(ty)
                        ),
                    ));
                }
                is_grid = true;
            }
            ("Piece", TagKind::Start | TagKind::Empty) => {
                if !is_grid {
                    return Err(
                        sc.error(line, "<Piece> outside <VTKFile type=\"UnstructuredGrid\">")
                    );
                }
                let count = |key: &str| -> Result<u64, MeshError> {
                    let v = tag.attr(key).unwrap_or("");
                    v.parse().map_err(|_| {
                        sc.error(
                            line,
                            format!("expected a count in {key}, found {}", quote(v)),
                        )
                    })
                };
                let p = Piece::new(count("NumberOfPoints")?, count("NumberOfCells")?, line);
                if tag.kind == TagKind::Empty {
                    p.finish(&mut raw, &sc)?;
                    pieces += 1;
                } else {
                    piece = Some(p);
                }
            }
            ("Piece", TagKind::End) => {
                let p = piece
                    .take()
                    .ok_or_else(|| sc.error(line, "</Piece> without <Piece>"))?;
                p.finish(&mut raw, &sc)?;
                pieces += 1;
            }
            ("Points", TagKind::Start) => section = Section::Points,
            ("Cells", TagKind::Start) => section = Section::Cells,
            ("Points" | "Cells", TagKind::End) => section = Section::Other,
            ("DataArray", TagKind::Start | TagKind::Empty) => {
                let (content, content_start) = if tag.kind == TagKind::Start {
                    sc.content_until("</DataArray", line)?
                } else {
                    ("", tag.end)
                };
                if section == Section::Other {
                    continue;
                }
                let p = piece
                    .as_mut()
                    .ok_or_else(|| sc.error(line, "<DataArray> outside a <Piece>"))?;
                let format = tag.attr("format").unwrap_or("ascii");
                let name = tag.attr("Name").unwrap_or("");
                if format != "ascii" {
                    let label = match section {
                        Section::Points => "the Points DataArray".to_string(),
                        _ => format!("DataArray {}", quote(name)),
                    };
                    return Err(sc.error(
                        line,
                        format!(
                            "{label} has format=\"{format}\"; only ascii .vtu data is supported (re-export with ASCII data)"
                        ),
                    ));
                }
                let mut c = Cursor::starting_at(content, origin, None, sc.line_at(content_start));
                match section {
                    Section::Points => p.read_points(&mut c, &tag, line, content)?,
                    _ => p.read_cell_array(&mut c, name, line, content)?,
                }
            }
            ("AppendedData", _) => break,
            _ => {}
        }
    }
    if !is_grid {
        return Err(sc.eof_error("<VTKFile type=\"UnstructuredGrid\">"));
    }
    if let Some(p) = piece {
        return Err(sc.error(p.line, "this <Piece> is never closed"));
    }
    if pieces == 0 {
        return Err(sc.eof_error("a <Piece>"));
    }
    Ok(raw)
}

/// Which part of a piece the scanner is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Points,
    Cells,
    Other,
}

/// Arrays of one `<Piece>` as they are read.
#[derive(Debug)]
struct Piece {
    n_points: u64,
    n_cells: u64,
    line: usize,
    points: Option<Vec<Vec3>>,
    /// Connectivity and the line of each index.
    conn: Option<(Vec<u32>, Vec<usize>)>,
    offsets: Option<(Vec<u64>, usize)>,
    types: Option<Vec<u32>>,
}

impl Piece {
    fn new(n_points: u64, n_cells: u64, line: usize) -> Self {
        Self {
            n_points,
            n_cells,
            line,
            points: None,
            conn: None,
            offsets: None,
            types: None,
        }
    }

    /// The points array: `3 × NumberOfPoints` numbers.
    fn read_points(
        &mut self,
        c: &mut Cursor<'_>,
        tag: &Tag<'_>,
        line: usize,
        content: &str,
    ) -> Result<(), MeshError> {
        if tag.attr("NumberOfComponents") != Some("3") {
            return Err(c.error(
                line,
                "the Points DataArray must have NumberOfComponents=\"3\"",
            ));
        }
        let n = self.n_points;
        let mut points = Vec::with_capacity(capacity(n, content));
        for i in 0..n {
            let mut xyz = [0.0f32; 3];
            for v in &mut xyz {
                let Some(token) = c.next_token() else {
                    return Err(c.error(
                        c.last_line(),
                        format!(
                            "the Points DataArray ends early: expected a coordinate of point {} of {n}",
                            i + 1
                        ),
                    ));
                };
                *v = token.parse(
                    c.origin(),
                    format_args!("a coordinate of point {} of {n}", i + 1),
                )?;
            }
            points.push(Vec3::from_array(xyz));
        }
        if let Some(t) = c.next_token() {
            return Err(c.error(
                t.line,
                format!(
                    "found {} after the {n} points of NumberOfPoints",
                    quote(t.text)
                ),
            ));
        }
        self.points = Some(points);
        Ok(())
    }

    /// One of the `connectivity`, `offsets` and `types` arrays (others are ignored).
    fn read_cell_array(
        &mut self,
        c: &mut Cursor<'_>,
        name: &str,
        line: usize,
        content: &str,
    ) -> Result<(), MeshError> {
        match name {
            "connectivity" => {
                let mut conn = Vec::with_capacity(capacity(u64::MAX, content));
                let mut lines = Vec::with_capacity(conn.capacity());
                while let Some(t) = c.next_token() {
                    let index: u64 = t.parse(c.origin(), "a point index")?;
                    if index >= self.n_points {
                        return Err(c.error(
                            t.line,
                            format!(
                                "connectivity references point {index}, but NumberOfPoints is {}",
                                self.n_points
                            ),
                        ));
                    }
                    conn.push(index as u32);
                    lines.push(t.line);
                }
                self.conn = Some((conn, lines));
            }
            "offsets" => {
                let values = read_all::<u64>(c, "an offset")?;
                if values.len() as u64 != self.n_cells {
                    return Err(c.error(
                        line,
                        format!(
                            "offsets has {} values, but NumberOfCells is {}",
                            values.len(),
                            self.n_cells
                        ),
                    ));
                }
                self.offsets = Some((values, line));
            }
            "types" => {
                let values = read_all::<u32>(c, "a cell type")?;
                if values.len() as u64 != self.n_cells {
                    return Err(c.error(
                        line,
                        format!(
                            "types has {} values, but NumberOfCells is {}",
                            values.len(),
                            self.n_cells
                        ),
                    ));
                }
                self.types = Some(values);
            }
            _ => {}
        }
        Ok(())
    }

    /// Check the piece is complete and append it to `raw`.
    fn finish(self, raw: &mut RawMesh, sc: &Scanner<'_>) -> Result<(), MeshError> {
        let missing = |what: &str| sc.error(self.line, format!("this <Piece> has no {what}"));
        let points = match self.points {
            Some(p) => p,
            None if self.n_points == 0 => Vec::new(),
            None => return Err(missing("<Points> array")),
        };
        let (conn, lines, offsets, types) = match (self.conn, self.offsets, self.types) {
            (Some((conn, lines)), Some((offsets, offsets_line)), Some(types)) => {
                (conn, lines, (offsets, offsets_line), types)
            }
            _ if self.n_cells == 0 => (Vec::new(), Vec::new(), (Vec::new(), 0), Vec::new()),
            (None, ..) => return Err(missing("connectivity array")),
            (_, None, _) => return Err(missing("offsets array")),
            (.., None) => return Err(missing("types array")),
        };
        let (offsets, offsets_line) = offsets;
        let mut runs = Vec::with_capacity(offsets.len());
        let mut start = 0usize;
        for &end in &offsets {
            let end = usize::try_from(end).unwrap_or(usize::MAX);
            if end < start || end > conn.len() {
                return Err(sc.error(
                    offsets_line,
                    format!(
                        "offset {end} is out of order or beyond the {} connectivity entries",
                        conn.len()
                    ),
                ));
            }
            runs.push((
                start,
                end - start,
                lines.get(start).copied().unwrap_or(offsets_line),
            ));
            start = end;
        }
        if start != conn.len() {
            return Err(sc.error(
                offsets_line,
                format!(
                    "the last offset is {start}, but connectivity has {} entries",
                    conn.len()
                ),
            ));
        }
        let (tets, warnings) = tets_from_cells(&CellList { conn, runs }, &types, sc.origin())?;
        let base = raw.positions.len() as u32;
        raw.tets
            .extend(tets.into_iter().map(|t| t.map(|v| v + base)));
        raw.positions.extend(points);
        raw.warnings.extend(warnings);
        Ok(())
    }
}

/// Every token of `c` parsed as `T`.
fn read_all<T: std::str::FromStr>(c: &mut Cursor<'_>, what: &str) -> Result<Vec<T>, MeshError> {
    let mut out = Vec::new();
    while let Some(t) = c.next_token() {
        out.push(t.parse(c.origin(), what)?);
    }
    Ok(out)
}

/// Validate a frame's indices and field lengths and names before writing.
fn check_frame(path: &Path, frame: &VtuFrame) -> Result<(), MeshError> {
    super::check_tets(frame.positions.len(), frame.tets)?;
    let invalid = |message: String| MeshError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
    };
    let (n, m) = (frame.positions.len(), frame.tets.len());
    let point_fields = frame
        .point_scalars
        .iter()
        .map(|(name, v)| (*name, v.len()))
        .chain(frame.point_vectors.iter().map(|(name, v)| (*name, v.len())));
    let cell_fields = frame.cell_scalars.iter().map(|(name, v)| (*name, v.len()));
    for (kind, count, unit, fields) in [
        ("point", n, "nodes", point_fields.collect::<Vec<_>>()),
        ("cell", m, "tets", cell_fields.collect()),
    ] {
        let mut seen = HashSet::new();
        for (name, len) in fields {
            if name.trim().is_empty() {
                return Err(invalid(format!("a {kind} field has an empty name")));
            }
            if !seen.insert(name) {
                return Err(invalid(format!("{kind} field {name:?} appears twice")));
            }
            if len != count {
                return Err(invalid(format!(
                    "{kind} field {name:?} has {len} values, but the mesh has {count} {unit}"
                )));
            }
        }
    }
    Ok(())
}

/// Append one `<DataArray>` with `components` per tuple, one tuple per line.
fn array<T>(
    s: &mut String,
    ty: &str,
    name: Option<&str>,
    components: usize,
    items: impl Iterator<Item = T>,
    mut write_item: impl FnMut(&mut String, T),
) {
    let _ = write!(s, "        <DataArray type=\"{ty}\"");
    if let Some(name) = name {
        let _ = write!(s, " Name=\"{}\"", escape_attr(name));
    }
    if components != 1 {
        let _ = write!(s, " NumberOfComponents=\"{components}\"");
    }
    s.push_str(" format=\"ascii\">\n");
    for item in items {
        s.push_str("          ");
        write_item(s, item);
        s.push('\n');
    }
    s.push_str("        </DataArray>\n");
}

/// Write a vector as three space-separated numbers.
fn vec3(s: &mut String, v: &Vec3) {
    let _ = write!(s, "{} {} {}", v.x, v.y, v.z);
}

#[cfg(test)]
mod tests {
    use super::super::format_checks::{
        assert_errors, assert_read_back, assert_two_tets_and_a_triangle, scratch,
    };
    use super::*;

    const TWO_TETS: &str = r#"<?xml version="1.0"?>
<!-- written by hand -->
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="3">
      <PointData Scalars="t">
        <DataArray type="Float64" Name="t" format="binary">AAAA</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0 0 0 1 0 0
          0 1 0 0 0 1
          1 1 1
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int32" Name="offsets" format="ascii">4 7 11</DataArray>
        <DataArray type="Int32" Name="connectivity" format="ascii">
          0 1 2 3
          0 1 2
          1 2 3 4
        </DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 5 10</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;

    fn vtu(text: &str) -> Result<RawMesh, MeshError> {
        parse_vtu(text, Path::new("m.vtu"))
    }

    #[test]
    fn hand_written_file_parses_and_skips_the_triangle() {
        assert_two_tets_and_a_triangle(&vtu(TWO_TETS).expect("valid"));
    }

    #[test]
    fn malformed_arrays_name_their_lines() {
        let cases = [
            (
                TWO_TETS.replace("1 2 3 4\n", "1 2 3 5\n"),
                "m.vtu:21: connectivity references point 5, but NumberOfPoints is 5",
            ),
            (
                TWO_TETS.replace("0 1 0 0 0 1", "0 1 0 0 x 1"),
                "m.vtu:12: expected a coordinate of point 4 of 5, found \"x\"",
            ),
            (
                TWO_TETS.replace("          1 1 1\n", ""),
                "m.vtu:13: the Points DataArray ends early: expected a coordinate of point 5 of 5",
            ),
            (
                TWO_TETS.replace("NumberOfPoints=\"5\"", "NumberOfPoints=\"4\""),
                "m.vtu:13: found \"1\" after the 4 points",
            ),
            (
                TWO_TETS.replace("4 7 11<", "4 7<"),
                "m.vtu:17: offsets has 2 values, but NumberOfCells is 3",
            ),
            (
                TWO_TETS.replace("10 5 10", "10 10 10"),
                "m.vtu:20: cell 1 has type 10 (4 points) but lists 3",
            ),
            (
                TWO_TETS.replace("4 7 11<", "4 7 12<"),
                "m.vtu:17: offset 12 is out of order",
            ),
        ];
        assert_errors(vtu, &cases);
    }

    #[test]
    fn structural_errors_are_clear() {
        let before = |marker: &str| TWO_TETS[..TWO_TETS.find(marker).unwrap_or(0)].to_string();
        let cases = [
            (
                TWO_TETS.replace("\"ascii\">\n          0 0 0", "\"binary\">\n 0 0 0"),
                "m.vtu:10: the Points DataArray has format=\"binary\"",
            ),
            (
                TWO_TETS.replace("UnstructuredGrid\" version", "PolyData\" version"),
                "m.vtu:3: only VTKFile type=\"UnstructuredGrid\"",
            ),
            (before("</Piece>"), "m.vtu:5: this <Piece> is never closed"),
            (
                before("1 1 1"),
                "m.vtu:10: this element is never closed with </DataArray>",
            ),
            (
                TWO_TETS.replace("<Piece NumberOfPoints", "<Piece NumberOfPoints=5 x"),
                "m.vtu:5: malformed tag: the value of NumberOfPoints",
            ),
            (
                TWO_TETS.replace(
                    r#"<DataArray type="UInt8" Name="types" format="ascii">10 5 10</DataArray>"#,
                    "",
                ),
                "m.vtu:5: this <Piece> has no types array",
            ),
            (String::new(), "m.vtu:0: the file is empty"),
            (
                "<?xml version=\"1.0\"?>\n<!-- nothing\n".into(),
                "m.vtu:2: this markup is never closed",
            ),
        ];
        assert_errors(vtu, &cases);
    }

    #[test]
    fn write_then_parse_round_trips_with_fields() {
        let dir = scratch("vtu-roundtrip");
        let positions: Vec<Vec3> = (0..6)
            .map(|i| Vec3::new(i as f32 * 0.013, -(i as f32), (i * i) as f32 * 1e-5))
            .collect();
        let tets = vec![[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]];
        let stress = [1.5e3, 0.0, -2.25];
        let velocity: Vec<Vec3> = positions.iter().map(|p| *p * 2.0).collect();
        let mass = [0.1f32; 6];
        let mut frame = VtuFrame::new(&positions, &tets);
        frame.cell_scalars.push(("von_mises", &stress));
        frame.point_vectors.push(("velocity", &velocity));
        frame.point_scalars.push(("mass <kg>", &mass));
        let path = dir.join("frame_0001.vtu");
        write_vtu(&path, &frame).expect("write");
        assert!(!dir.join("frame_0001.vtu.tmp").exists());
        let text = std::fs::read_to_string(&path).expect("read");
        assert!(text.contains("Name=\"mass &lt;kg&gt;\""));
        assert!(text.contains("<DataArray type=\"Float32\" Name=\"von_mises\" format=\"ascii\">"));
        assert_read_back(&vtu(&text).expect("parse back"), &positions, &tets);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn writer_rejects_mismatched_fields_by_name() {
        let dir = scratch("vtu-mismatch");
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let tets = [[0, 1, 2, 3]];
        let two = [1.0f32, 2.0];
        let path = dir.join("bad.vtu");
        let mut frame = VtuFrame::new(&positions, &tets);
        frame.cell_scalars.push(("stress", &two));
        let msg = write_vtu(&path, &frame)
            .expect_err("2 values for 1 tet")
            .to_string();
        assert!(
            msg.contains("cell field \"stress\" has 2 values, but the mesh has 1 tets"),
            "{msg}"
        );
        let mut frame = VtuFrame::new(&positions, &tets);
        frame.point_scalars.push(("damage", &two));
        let msg = write_vtu(&path, &frame)
            .expect_err("2 values for 4 nodes")
            .to_string();
        assert!(
            msg.contains("point field \"damage\" has 2 values, but the mesh has 4 nodes"),
            "{msg}"
        );
        let v = [Vec3::ZERO; 4];
        let one = [0.0f32];
        let mut frame = VtuFrame::new(&positions, &tets);
        frame.point_vectors.push(("u", &v));
        frame.point_vectors.push(("u", &v));
        frame.cell_scalars.push(("s", &one));
        let msg = write_vtu(&path, &frame).expect_err("duplicate").to_string();
        assert!(msg.contains("point field \"u\" appears twice"), "{msg}");
        let bad_tets = [[0, 1, 2, 4]];
        let frame = VtuFrame::new(&positions, &bad_tets);
        assert!(matches!(
            write_vtu(&path, &frame),
            Err(MeshError::NodeIndexOutOfRange { node: 4, .. })
        ));
        assert!(!path.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn empty_frame_writes_a_valid_empty_grid() {
        let dir = scratch("vtu-empty");
        let path = dir.join("empty.vtu");
        write_vtu(&path, &VtuFrame::default()).expect("write");
        let raw = super::super::load_mesh(&path).expect("parse");
        assert!(raw.positions.is_empty() && raw.tets.is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }

    proptest::proptest! {
        #[test]
        fn truncations_and_noise_never_panic(
            cut in 0usize..1200,
            noise in "[0-9 <>/=\"'!?a-zA-Z\n-]{0,200}",
        ) {
            let mut cut = cut.min(TWO_TETS.len());
            while !TWO_TETS.is_char_boundary(cut) {
                cut -= 1;
            }
            let _ = vtu(&TWO_TETS[..cut]);
            let _ = vtu(&format!("{}{noise}", &TWO_TETS[..cut]));
            let _ = vtu(&noise);
        }
    }
}
