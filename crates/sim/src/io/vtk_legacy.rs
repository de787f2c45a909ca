//! Legacy VTK (`.vtk`) ASCII unstructured grids: reader and writer.
//!
//! The reader takes `DATASET UNSTRUCTURED_GRID` with `POINTS`, `CELLS` (the classic
//! `<count> <ids..>` layout and the 5.1 `OFFSETS`/`CONNECTIVITY` layout) and `CELL_TYPES`.
//! Tetra cells (type 10, and quadratic tetra 24 by their corners) become tets; other cell
//! types are skipped with one warning per type. `FIELD` data is skipped, and everything from
//! `POINT_DATA`/`CELL_DATA` on is ignored.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use super::atomic::write_atomic;
use super::text::{Cursor, Fields, capacity, quote};
use super::vtk_cells::{CellList, VTK_TETRA, tets_from_cells};
use crate::{MeshError, RawMesh};

/// Parse a legacy VTK ASCII unstructured grid; `origin` names it in errors.
pub fn parse_vtk(text: &str, origin: &Path) -> Result<RawMesh, MeshError> {
    let mut c = Cursor::new(text, origin, None);
    read_preamble(&mut c)?;
    let mut dataset = false;
    let mut points: Option<Vec<Vec3>> = None;
    let mut cells: Option<CellList> = None;
    let mut types: Option<Vec<u32>> = None;
    while let Some(mut line) = c.next_line() {
        let keyword = line.next_str("a keyword")?.to_ascii_uppercase();
        match keyword.as_str() {
            "DATASET" => {
                let kind = line.next_str("a dataset type")?;
                if !kind.eq_ignore_ascii_case("UNSTRUCTURED_GRID") {
                    return Err(line.error(format!(
                        "only DATASET UNSTRUCTURED_GRID is supported, found {}",
                        quote(kind)
                    )));
                }
                dataset = true;
            }
            _ if !dataset => return Err(line.unexpected("DATASET UNSTRUCTURED_GRID")),
            "POINTS" => {
                let n: u64 = line.next("the number of points")?;
                let _ty = line.next_str("the point data type (float or double)")?;
                points = Some(read_points(&mut c, n, text)?);
            }
            "CELLS" => {
                let Some(points) = &points else {
                    return Err(line.error("CELLS comes before POINTS"));
                };
                let n: u64 = line.next("the number of cells")?;
                let size: u64 = line.next("the size of the cell list")?;
                let list = if c.peek().is_some_and(|t| t.eq_ignore_ascii_case("OFFSETS")) {
                    read_cells_51(&mut c, n, size, points.len(), text)?
                } else {
                    read_cells_classic(&mut c, n, size, points.len(), text, line.line())?
                };
                cells = Some(list);
            }
            "CELL_TYPES" => {
                let Some(list) = &cells else {
                    return Err(line.error("CELL_TYPES comes before CELLS"));
                };
                let n: u64 = line.next("the number of cell types")?;
                if n != list.runs.len() as u64 {
                    return Err(line.error(format!(
                        "CELL_TYPES announces {n} cells, but CELLS has {}",
                        list.runs.len()
                    )));
                }
                let mut t = Vec::with_capacity(list.runs.len());
                for i in 0..n {
                    t.push(
                        c.value(format_args!("the type of cell {} of {n}", i + 1))?
                            .0,
                    );
                }
                no_more_on_line(&mut c, n, "cell types")?;
                types = Some(t);
            }
            "FIELD" => skip_field(&mut c, &mut line)?,
            "POINT_DATA" | "CELL_DATA" => break,
            k if k.starts_with(|ch: char| ch.is_ascii_digit() || ch == '-' || ch == '.') => {
                return Err(line.unexpected(
                    "a keyword such as CELLS (does the previous section's count match its data?)",
                ));
            }
            // METADATA and similar informational lines.
            _ => {}
        }
    }
    if !dataset {
        return Err(c.eof_error("DATASET UNSTRUCTURED_GRID"));
    }
    let positions = points.ok_or_else(|| c.eof_error("a POINTS section"))?;
    let cells = cells.ok_or_else(|| c.eof_error("a CELLS section"))?;
    let types = types.ok_or_else(|| c.eof_error("a CELL_TYPES section"))?;
    let (tets, warnings) = tets_from_cells(&cells, &types, origin)?;
    Ok(RawMesh {
        positions,
        tets,
        warnings,
        boundary_faces: None,
    })
}

/// Write `positions` and `tets` as a legacy VTK 3.0 ASCII unstructured grid, atomically.
pub fn write_vtk(path: &Path, positions: &[Vec3], tets: &[[u32; 4]]) -> Result<(), MeshError> {
    super::check_tets(positions.len(), tets)?;
    let mut s = String::with_capacity(32 * (positions.len() + tets.len()) + 128);
    s.push_str("# vtk DataFile Version 3.0\nincise tet mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n");
    let _ = writeln!(s, "POINTS {} float", positions.len());
    for p in positions {
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }
    let _ = writeln!(s, "CELLS {} {}", tets.len(), 5 * tets.len());
    for t in tets {
        let _ = writeln!(s, "4 {} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    let _ = writeln!(s, "CELL_TYPES {}", tets.len());
    for _ in tets {
        let _ = writeln!(s, "{VTK_TETRA}");
    }
    write_atomic(path, s.as_bytes())
}

/// The header line, the title line and `ASCII`.
fn read_preamble(c: &mut Cursor<'_>) -> Result<(), MeshError> {
    let header_what = "the header \"# vtk DataFile Version 3.0\"";
    let (line, header) = c.raw_line().ok_or_else(|| c.eof_error(header_what))?;
    if !header
        .trim()
        .to_ascii_lowercase()
        .starts_with("# vtk datafile version")
    {
        return Err(c.error(
            line,
            format!("expected {header_what}, found {}", quote(header.trim())),
        ));
    }
    c.raw_line().ok_or_else(|| c.eof_error("the title line"))?;
    let format = c.expect_line("ASCII or BINARY")?;
    match format.text().to_ascii_uppercase().as_str() {
        "ASCII" => Ok(()),
        "BINARY" => Err(format.error("binary .vtk is not supported; re-export as ASCII")),
        _ => Err(format.unexpected("ASCII or BINARY")),
    }
}

/// The `3 n` coordinates after a `POINTS n <type>` line.
fn read_points(c: &mut Cursor<'_>, n: u64, text: &str) -> Result<Vec<Vec3>, MeshError> {
    let mut points = Vec::with_capacity(capacity(n, text));
    for i in 0..n {
        let mut xyz = [0.0f32; 3];
        for v in &mut xyz {
            *v = c
                .value(format_args!("a coordinate of point {} of {n}", i + 1))?
                .0;
        }
        points.push(Vec3::from_array(xyz));
    }
    no_more_on_line(c, n, "points")?;
    Ok(points)
}

/// A point index below `count`, with the line it is on.
fn point_index(c: &mut Cursor<'_>, cell: u64, count: usize) -> Result<(u32, usize), MeshError> {
    let (index, line): (u64, usize) = c.value(format_args!("a point index of cell {cell}"))?;
    if index >= count as u64 {
        return Err(c.error(
            line,
            format!("cell {cell} references point {index}, but POINTS has {count}"),
        ));
    }
    Ok((index as u32, line))
}

/// Classic `CELLS n size` body: per cell `<count> <ids..>`, `size` numbers in all.
fn read_cells_classic(
    c: &mut Cursor<'_>,
    n: u64,
    size: u64,
    points: usize,
    text: &str,
    header_line: usize,
) -> Result<CellList, MeshError> {
    let mut list = CellList {
        conn: Vec::with_capacity(capacity(size, text)),
        runs: Vec::with_capacity(capacity(n, text)),
    };
    let mut numbers = 0u64;
    for k in 0..n {
        let (len, line): (u64, usize) =
            c.value(format_args!("the point count of cell {k} of {n}"))?;
        let start = list.conn.len();
        for _ in 0..len {
            list.conn.push(point_index(c, k, points)?.0);
        }
        list.runs.push((start, list.conn.len() - start, line));
        numbers += len + 1;
    }
    no_more_on_line(c, n, "cells")?;
    if numbers != size {
        return Err(c.error(
            header_line,
            format!("CELLS announces a list of {size} numbers, but its cells hold {numbers}"),
        ));
    }
    Ok(list)
}

/// VTK 5.1 `CELLS <offsets> <connectivity>` body: `OFFSETS <type>` then the offsets,
/// `CONNECTIVITY <type>` then the point indices.
fn read_cells_51(
    c: &mut Cursor<'_>,
    n_offsets: u64,
    size: u64,
    points: usize,
    text: &str,
) -> Result<CellList, MeshError> {
    keyword_line(c, "OFFSETS")?;
    let mut offsets = Vec::with_capacity(capacity(n_offsets, text));
    let mut previous = 0u64;
    for i in 0..n_offsets {
        let (offset, line): (u64, usize) = c.value(format_args!("offset {i} of {n_offsets}"))?;
        if (i == 0 && offset != 0) || offset < previous || offset > size {
            return Err(c.error(
                line,
                format!("offset {offset} must start at 0, not decrease, and stay <= {size}"),
            ));
        }
        offsets.push((offset as usize, line));
        previous = offset;
    }
    if previous != size {
        return Err(c.error(
            c.last_line(),
            format!("the last offset is {previous}, but CELLS announces {size} indices"),
        ));
    }
    no_more_on_line(c, n_offsets, "offsets")?;
    keyword_line(c, "CONNECTIVITY")?;
    let mut list = CellList {
        conn: Vec::with_capacity(capacity(size, text)),
        runs: Vec::with_capacity(offsets.len()),
    };
    for (k, pair) in offsets.windows(2).enumerate() {
        let (start, end) = (pair[0].0, pair[1].0);
        let mut line = pair[1].1;
        for j in start..end {
            let (index, at) = point_index(c, k as u64, points)?;
            if j == start {
                line = at;
            }
            list.conn.push(index);
        }
        list.runs.push((start, end - start, line));
    }
    no_more_on_line(c, size, "indices")?;
    Ok(list)
}

/// A line that starts with `keyword` (its data type is ignored).
fn keyword_line(c: &mut Cursor<'_>, keyword: &str) -> Result<(), MeshError> {
    let token = c.token(keyword)?;
    if !token.text.eq_ignore_ascii_case(keyword) {
        return Err(c.error(
            token.line,
            format!("expected {keyword}, found {}", quote(token.text)),
        ));
    }
    c.end_line();
    Ok(())
}

/// After reading the announced `n` items, the current line must hold nothing more.
fn no_more_on_line(c: &mut Cursor<'_>, n: u64, what: &str) -> Result<(), MeshError> {
    match c.next_on_line() {
        Some(t) => Err(c.error(
            t.line,
            format!("found {} after the {n} {what} announced", quote(t.text)),
        )),
        None => Ok(()),
    }
}

/// Skip `FIELD <name> <arrays>`: per array `<name> <components> <tuples> <type>` and values.
fn skip_field(c: &mut Cursor<'_>, line: &mut Fields<'_>) -> Result<(), MeshError> {
    let _name = line.next_str("the field name")?;
    let arrays: u64 = line.next("the number of field arrays")?;
    for a in 0..arrays {
        let mut head = c.expect_line(format_args!("field array {} of {arrays}", a + 1))?;
        let _name = head.next_str("the array name")?;
        let components: u64 = head.next("the number of components")?;
        let tuples: u64 = head.next("the number of tuples")?;
        let _ty = head.next_str("the array data type")?;
        let values = components
            .checked_mul(tuples)
            .ok_or_else(|| head.error("the array size overflows"))?;
        for _ in 0..values {
            c.token("a field value")?;
        }
        c.end_line();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::format_checks::{
        assert_errors, assert_read_back, assert_two_tets_and_a_triangle, scratch,
    };
    use super::*;

    const TWO_TETS: &str = "\
# vtk DataFile Version 3.0

ASCII
DATASET UNSTRUCTURED_GRID
FIELD FieldData 1
TIME 1 1 double
0.5
POINTS 5 double
0 0 0 1 0 0 0 1 0
0 0 1
1 1 1
CELLS 3 14
4 0 1 2 3
3 0 1 2
4 1 2 3 4
CELL_TYPES 3
10 5
10
CELL_DATA 3
SCALARS id int 1
LOOKUP_TABLE default
1 2 3
";

    const VTK51: &str = "\
# vtk DataFile Version 5.1
vtk output
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 5 float
0 0 0 1 0 0 0 1 0
0 0 1 1 1 1
METADATA
INFORMATION 0

CELLS 4 8
OFFSETS vtktypeint64
0 4 7 8
CONNECTIVITY vtktypeint64
0 1 2 3
0 1 2
4
CELL_TYPES 3
10
5
1
";

    fn vtk(text: &str) -> Result<RawMesh, MeshError> {
        parse_vtk(text, Path::new("m.vtk"))
    }

    #[test]
    fn classic_layout_with_field_data_and_skipped_triangle() {
        assert_two_tets_and_a_triangle(&vtk(TWO_TETS).expect("valid"));
    }

    #[test]
    fn version_51_offsets_layout() {
        let raw = vtk(VTK51).expect("valid 5.1");
        assert_eq!(raw.positions.len(), 5);
        assert_eq!(raw.tets, vec![[0, 1, 2, 3]]);
        assert_eq!(
            raw.warnings,
            vec![
                "skipped 1 cell of VTK type 1 (vertex)",
                "skipped 1 cell of VTK type 5 (triangle)"
            ]
        );
    }

    #[test]
    fn out_of_range_point_names_the_cell_line() {
        let cases = [
            (
                TWO_TETS.replace("4 1 2 3 4", "4 1 2 3 5"),
                "m.vtk:15: cell 2 references point 5, but POINTS has 5",
            ),
            (
                VTK51.replace("0 1 2\n4", "0 1 2\n7"),
                "m.vtk:17: cell 2 references point 7",
            ),
        ];
        assert_errors(vtk, &cases);
    }

    #[test]
    fn wrong_counts_are_errors_with_lines() {
        let cases = [
            (
                TWO_TETS.replace("1 1 1\nCELLS", "CELLS"),
                "m.vtk:11: expected a coordinate of point 5 of 5, found \"CELLS\"",
            ),
            (
                TWO_TETS.replace("POINTS 5", "POINTS 4"),
                "m.vtk:11: expected a keyword such as CELLS",
            ),
            (
                TWO_TETS.replace("CELLS 3 14", "CELLS 3 15"),
                "m.vtk:12: CELLS announces a list of 15 numbers",
            ),
            (
                TWO_TETS.replace("CELL_TYPES 3", "CELL_TYPES 2"),
                "m.vtk:16: CELL_TYPES announces 2 cells, but CELLS has 3",
            ),
            (
                TWO_TETS.replace("3 0 1 2", "4 0 1 2"),
                "m.vtk:15: found \"3\" after the 3 cells announced",
            ),
            (
                TWO_TETS.replace("10 5", "10 10"),
                "m.vtk:14: cell 1 has type 10 (4 points) but lists 3",
            ),
            (
                VTK51.replace("0 4 7 8", "0 4 3 8"),
                "m.vtk:13: offset 3 must start at 0, not decrease",
            ),
        ];
        assert_errors(vtk, &cases);
    }

    #[test]
    fn truncated_non_numeric_and_empty_inputs_are_errors() {
        let before = |marker: &str| TWO_TETS[..TWO_TETS.find(marker).unwrap_or(0)].to_string();
        let cases = [
            (
                before("CELL_TYPES"),
                "m.vtk:15: unexpected end of file: expected a CELL_TYPES",
            ),
            (
                before("4 1 2 3 4"),
                "m.vtk:14: unexpected end of file: expected the point count",
            ),
            (
                TWO_TETS.replace("0 0 1\n", "0 O 1\n"),
                "m.vtk:10: expected a coordinate of point 4 of 5, found \"O\"",
            ),
            (String::new(), "m.vtk:0: the file is empty"),
            (
                "# vtk DataFile Version 3.0\nt\nBINARY\n".into(),
                "m.vtk:3: binary .vtk is not supported",
            ),
            (
                "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n".into(),
                "m.vtk:4: only DATASET UNSTRUCTURED_GRID is supported",
            ),
            (
                "ply\nformat ascii 1.0\n".into(),
                "m.vtk:1: expected the header",
            ),
        ];
        assert_errors(vtk, &cases);
    }

    #[test]
    fn write_then_parse_round_trips() {
        let dir = scratch("vtk");
        let positions: Vec<Vec3> = (0..7)
            .map(|i| {
                Vec3::new(
                    i as f32 * 0.1,
                    (i as f32).sin() * 1e-3,
                    1e4 - i as f32 / 7.0,
                )
            })
            .collect();
        let tets = vec![[0, 1, 2, 3], [6, 5, 4, 3], [2, 4, 6, 0]];
        let path = dir.join("mesh.vtk");
        write_vtk(&path, &positions, &tets).expect("write");
        let raw = super::super::load_mesh(&path).expect("read back");
        assert_read_back(&raw, &positions, &tets);
        let _ = std::fs::remove_dir_all(&dir);
    }

    proptest::proptest! {
        #[test]
        fn truncations_and_noise_never_panic(
            cut in 0usize..600,
            noise in "[0-9 .a-zA-Z_\n-]{0,300}",
        ) {
            for sample in [TWO_TETS, VTK51] {
                let _ = vtk(&sample[..cut.min(sample.len())]);
                let _ = vtk(&format!("{}{noise}", &sample[..cut.min(sample.len())]));
            }
            let _ = vtk(&noise);
        }
    }
}
