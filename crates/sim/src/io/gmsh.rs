//! Gmsh `.msh` reader: MSH 2.2 and 4.1, ASCII only.
//!
//! Node tags (possibly non-contiguous) are mapped to 0-based indices in file order.
//! 4-node (type 4) and 10-node (type 11, corners kept) tets are read; every other element
//! type is skipped with one warning per type. Sections other than `$MeshFormat`, `$Nodes`
//! and `$Elements` are skipped.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use glam::Vec3;

use super::text::{Cursor, Fields, capacity};
use crate::{MeshError, RawMesh};

/// Gmsh element type of a 4-node tetrahedron.
pub const TET4: u64 = 4;
/// Gmsh element type of a 10-node (second-order) tetrahedron.
pub const TET10: u64 = 11;

/// The two supported MSH layouts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Version {
    /// MSH 2.x: one line per node and per element.
    V2,
    /// MSH 4.1: nodes and elements grouped in entity blocks.
    V41,
}

/// Nodes read so far: coordinates and tag -> index.
#[derive(Debug, Default)]
struct Nodes {
    positions: Vec<Vec3>,
    index_of_tag: HashMap<u64, u32>,
}

/// Tets read so far and the elements skipped, by type.
#[derive(Debug, Default)]
struct Elements {
    tets: Vec<[u32; 4]>,
    skipped: BTreeMap<u64, u64>,
}

/// Parse an ASCII MSH 2.2 or 4.1 file; `origin` names it in errors.
pub fn parse_msh(text: &str, origin: &Path) -> Result<RawMesh, MeshError> {
    let mut c = Cursor::new(text, origin, None);
    let first = c.expect_line("$MeshFormat")?;
    if first.text() != "$MeshFormat" {
        return Err(first.unexpected("$MeshFormat (is this a Gmsh .msh file?)"));
    }
    let version = read_format(&mut c)?;
    let mut nodes: Option<Nodes> = None;
    let mut elements: Option<Elements> = None;
    while let Some(line) = c.next_line() {
        match line.text() {
            "$Nodes" => {
                if nodes.is_some() {
                    return Err(line.error("a second $Nodes section is not supported"));
                }
                nodes = Some(match version {
                    Version::V2 => read_nodes_v2(&mut c, text)?,
                    Version::V41 => read_nodes_v41(&mut c, text)?,
                });
            }
            "$Elements" => {
                let Some(nodes) = &nodes else {
                    return Err(line.error("$Elements comes before $Nodes"));
                };
                if elements.is_some() {
                    return Err(line.error("a second $Elements section is not supported"));
                }
                elements = Some(match version {
                    Version::V2 => read_elements_v2(&mut c, nodes, text)?,
                    Version::V41 => read_elements_v41(&mut c, nodes, text)?,
                });
            }
            name if name.starts_with('$') && !name.starts_with("$End") => {
                skip_section(&mut c, &name[1..])?;
            }
            _ => return Err(line.unexpected("a section such as $Nodes or $Elements")),
        }
    }
    let nodes = nodes.ok_or_else(|| c.eof_error("a $Nodes section"))?;
    let elements = elements.ok_or_else(|| c.eof_error("an $Elements section"))?;
    let warnings = elements
        .skipped
        .iter()
        .map(|(&ty, &n)| skipped_warning(ty, n))
        .collect();
    Ok(RawMesh {
        positions: nodes.positions,
        tets: elements.tets,
        warnings,
        boundary_faces: None,
    })
}

/// The body of `$MeshFormat` (`<version> <file-type> <data-size>`) and its end marker.
fn read_format(c: &mut Cursor<'_>) -> Result<Version, MeshError> {
    let mut line = c.expect_line("the format line \"<version> 0 8\"")?;
    let version = line.next_str("the MSH version")?;
    let file_type: u32 = line.next("the file type (0 for ASCII)")?;
    if file_type != 0 {
        return Err(line.error("binary .msh is not supported; re-export as ASCII"));
    }
    let version = match version {
        "4.1" => Version::V41,
        v if v == "2" || v.starts_with("2.") => Version::V2,
        v => {
            return Err(line.error(format!(
                "MSH version {v} is not supported; re-export as version 4.1 or 2.2 ASCII"
            )));
        }
    };
    end_marker(c, "$EndMeshFormat")?;
    Ok(version)
}

/// MSH 2: `<count>`, then `<tag> <x> <y> <z>` per node.
fn read_nodes_v2(c: &mut Cursor<'_>, text: &str) -> Result<Nodes, MeshError> {
    let count: u64 = c
        .expect_line("the number of nodes")?
        .next("the number of nodes")?;
    let mut nodes = Nodes::with_capacity(capacity(count, text));
    for i in 0..count {
        let mut line = data_line(c, "a node line", i, count, "nodes")?;
        let tag = line.next("a node tag")?;
        let position = read_xyz(&mut line)?;
        nodes.push(tag, position, &line)?;
    }
    end_marker(c, "$EndNodes")?;
    Ok(nodes)
}

/// MSH 4.1: `<blocks> <count> <min tag> <max tag>`, then per block
/// `<dim> <entity> <parametric> <n>`, `n` tag lines and `n` coordinate lines.
fn read_nodes_v41(c: &mut Cursor<'_>, text: &str) -> Result<Nodes, MeshError> {
    let mut header = c.expect_line("the $Nodes header \"<blocks> <nodes> <min tag> <max tag>\"")?;
    let blocks: u64 = header.next("the number of entity blocks")?;
    let count: u64 = header.next("the number of nodes")?;
    let mut nodes = Nodes::with_capacity(capacity(count, text));
    let mut read = 0u64;
    for _ in 0..blocks {
        let mut block = data_line(c, "a node block header", read, count, "nodes")?;
        let _dim: u64 = block.next("the entity dimension")?;
        let _entity: i64 = block.next("the entity tag")?;
        let _parametric: u64 = block.next("the parametric flag")?;
        let in_block: u64 = block.next("the number of nodes in the block")?;
        let mut tags = Vec::with_capacity(capacity(in_block, text));
        for i in 0..in_block {
            let tag = data_line(c, "a node tag", read + i, count, "nodes")?.next("a node tag")?;
            tags.push(tag);
        }
        for (i, &tag) in tags.iter().enumerate() {
            let mut line = data_line(c, "node coordinates", read + i as u64, count, "nodes")?;
            let position = read_xyz(&mut line)?;
            nodes.push(tag, position, &line)?;
        }
        read += in_block;
    }
    if read != count {
        return Err(header.error(format!(
            "the header announces {count} nodes, but its blocks hold {read}"
        )));
    }
    end_marker(c, "$EndNodes")?;
    Ok(nodes)
}

/// MSH 2: `<count>`, then `<tag> <type> <ntags> <tags..> <nodes..>` per element.
fn read_elements_v2(c: &mut Cursor<'_>, nodes: &Nodes, text: &str) -> Result<Elements, MeshError> {
    let count: u64 = c
        .expect_line("the number of elements")?
        .next("the number of elements")?;
    let mut out = Elements::with_capacity(capacity(count, text));
    for i in 0..count {
        let mut line = data_line(c, "an element line", i, count, "elements")?;
        let tag: u64 = line.next("an element tag")?;
        let ty: u64 = line.next("an element type")?;
        if ty != TET4 && ty != TET10 {
            *out.skipped.entry(ty).or_default() += 1;
            continue;
        }
        let ntags: u64 = line.next("the number of element tags")?;
        for _ in 0..ntags {
            line.next_str("an element tag")?;
        }
        out.tets.push(read_tet(&mut line, tag, nodes)?);
    }
    end_marker(c, "$EndElements")?;
    Ok(out)
}

/// MSH 4.1: `<blocks> <count> <min tag> <max tag>`, then per block
/// `<dim> <entity> <type> <n>` and `n` lines `<tag> <nodes..>`.
fn read_elements_v41(c: &mut Cursor<'_>, nodes: &Nodes, text: &str) -> Result<Elements, MeshError> {
    let mut header =
        c.expect_line("the $Elements header \"<blocks> <elements> <min tag> <max tag>\"")?;
    let blocks: u64 = header.next("the number of entity blocks")?;
    let count: u64 = header.next("the number of elements")?;
    let mut out = Elements::with_capacity(capacity(count, text));
    let mut read = 0u64;
    for _ in 0..blocks {
        let mut block = data_line(c, "an element block header", read, count, "elements")?;
        let _dim: u64 = block.next("the entity dimension")?;
        let _entity: i64 = block.next("the entity tag")?;
        let ty: u64 = block.next("an element type")?;
        let in_block: u64 = block.next("the number of elements in the block")?;
        let keep = ty == TET4 || ty == TET10;
        for i in 0..in_block {
            let mut line = data_line(c, "an element line", read + i, count, "elements")?;
            let tag: u64 = line.next("an element tag")?;
            if keep {
                out.tets.push(read_tet(&mut line, tag, nodes)?);
            }
        }
        if !keep && in_block > 0 {
            *out.skipped.entry(ty).or_default() += in_block;
        }
        read += in_block;
    }
    if read != count {
        return Err(header.error(format!(
            "the header announces {count} elements, but its blocks hold {read}"
        )));
    }
    end_marker(c, "$EndElements")?;
    Ok(out)
}

/// The first four node tags of a tet element, as node indices.
fn read_tet(line: &mut Fields<'_>, tag: u64, nodes: &Nodes) -> Result<[u32; 4], MeshError> {
    let mut tet = [0u32; 4];
    for slot in &mut tet {
        let node: u64 = line.next("a node tag")?;
        *slot = *nodes.index_of_tag.get(&node).ok_or_else(|| {
            line.error(format!(
                "element {tag} references node {node}, which is not in $Nodes"
            ))
        })?;
    }
    Ok(tet)
}

/// Three coordinates; trailing parametric coordinates are ignored.
fn read_xyz(line: &mut Fields<'_>) -> Result<Vec3, MeshError> {
    let x = line.next("an x coordinate")?;
    let y = line.next("a y coordinate")?;
    let z = line.next("a z coordinate")?;
    Ok(Vec3::new(x, y, z))
}

/// The next line of a section body, which must not be a `$` marker yet.
fn data_line<'a>(
    c: &mut Cursor<'a>,
    what: &str,
    done: u64,
    count: u64,
    items: &str,
) -> Result<Fields<'a>, MeshError> {
    let line = c.expect_line(what)?;
    if line.text().starts_with('$') {
        return Err(line.error(format!(
            "expected {what}, found {}: the header announces {count} {items}, only {done} came",
            super::text::quote(line.text())
        )));
    }
    Ok(line)
}

/// The next line must be exactly `marker`.
fn end_marker(c: &mut Cursor<'_>, marker: &str) -> Result<(), MeshError> {
    let line = c.expect_line(marker)?;
    if line.text() != marker {
        return Err(line.unexpected(format!("{marker} (does the header count match the data?)")));
    }
    Ok(())
}

/// Skip the body of section `$name` up to `$Endname`.
fn skip_section(c: &mut Cursor<'_>, name: &str) -> Result<(), MeshError> {
    let end = format!("$End{name}");
    while let Some(line) = c.next_line() {
        if line.text() == end {
            return Ok(());
        }
    }
    Err(c.eof_error(&end))
}

/// The warning for `count` skipped elements of Gmsh type `ty`.
fn skipped_warning(ty: u64, count: u64) -> String {
    let noun = if count == 1 { "element" } else { "elements" };
    match type_name(ty) {
        Some(name) => format!("skipped {count} {noun} of Gmsh type {ty} ({name})"),
        None => format!("skipped {count} {noun} of Gmsh type {ty}"),
    }
}

/// Human name of a Gmsh element type.
fn type_name(ty: u64) -> Option<&'static str> {
    Some(match ty {
        1 => "2-node line",
        2 => "3-node triangle",
        3 => "4-node quadrangle",
        4 => "4-node tetrahedron",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node line",
        9 => "6-node triangle",
        10 => "9-node quadrangle",
        11 => "10-node tetrahedron",
        12 => "27-node hexahedron",
        13 => "18-node prism",
        14 => "14-node pyramid",
        15 => "1-node point",
        16 => "8-node quadrangle",
        17 => "20-node hexahedron",
        18 => "15-node prism",
        19 => "13-node pyramid",
        _ => return None,
    })
}

impl Nodes {
    fn with_capacity(n: usize) -> Self {
        Self {
            positions: Vec::with_capacity(n),
            index_of_tag: HashMap::with_capacity(n),
        }
    }

    /// Add node `tag`; a repeated tag is an error at `line`.
    fn push(&mut self, tag: u64, position: Vec3, line: &Fields<'_>) -> Result<(), MeshError> {
        let index = self.positions.len() as u32;
        if self.index_of_tag.insert(tag, index).is_some() {
            return Err(line.error(format!("node tag {tag} appears twice")));
        }
        self.positions.push(position);
        Ok(())
    }
}

impl Elements {
    fn with_capacity(n: usize) -> Self {
        Self {
            tets: Vec::with_capacity(n),
            skipped: BTreeMap::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tets, node tags 10..50 in steps of 10 in two blocks, and a skipped triangle.
    const MSH41: &str = "\
$MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 0 0 1
1 0 0 0 1 1 1 0 0
$EndEntities
$Nodes
2 5 10 50
3 1 0 3
10
20
30
0 0 0
1 0 0
0 1 0
3 1 0 2
40
50
0 0 1
1 1 1
$EndNodes
$Elements
2 3 1 3
2 1 2 1
1 10 20 30
3 1 11 2
2 10 20 30 40 11 12 13 14 15 16
3 20 30 40 50 11 12 13 14 15 16
$EndElements
";

    const MSH22: &str = "\
$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 \"tissue\"
$EndPhysicalNames
$Nodes
5
1 0 0 0
2 1 0 0
3 0 1 0
7 0 0 1
9 1 1 1
$EndNodes
$Elements
4
1 15 2 0 1 1
2 2 2 0 1 1 2 3
3 4 2 1 1 1 2 3 7
4 4 2 1 1 2 3 7 9
$EndElements
";

    fn msh(text: &str) -> Result<RawMesh, MeshError> {
        parse_msh(text, Path::new("m.msh"))
    }

    fn err_text(text: &str) -> String {
        msh(text).expect_err("input is malformed").to_string()
    }

    fn expected_positions() -> Vec<Vec3> {
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE]
    }

    #[test]
    fn v41_blocks_with_sparse_tags_map_to_indices_and_skip_triangles() {
        let raw = msh(MSH41).expect("valid 4.1");
        assert_eq!(raw.positions, expected_positions());
        assert_eq!(raw.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
        assert_eq!(
            raw.warnings,
            vec!["skipped 1 element of Gmsh type 2 (3-node triangle)".to_string()]
        );
    }

    #[test]
    fn v22_with_physical_tags_and_skipped_types() {
        let raw = msh(MSH22).expect("valid 2.2");
        assert_eq!(raw.positions, expected_positions());
        assert_eq!(raw.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
        assert_eq!(
            raw.warnings,
            vec![
                "skipped 1 element of Gmsh type 2 (3-node triangle)".to_string(),
                "skipped 1 element of Gmsh type 15 (1-node point)".to_string(),
            ]
        );
    }

    #[test]
    fn skipped_warning_counts_a_whole_block() {
        let text = MSH41.replace("2 1 2 1\n1 10 20 30\n", "2 1 2 2\n1 10 20 30\n7 20 30 40\n");
        let text = text.replace("2 3 1 3\n", "2 4 1 7\n");
        let raw = msh(&text).expect("valid");
        assert_eq!(
            raw.warnings,
            vec!["skipped 2 elements of Gmsh type 2 (3-node triangle)"]
        );
    }

    #[test]
    fn binary_and_unknown_versions_are_refused_clearly() {
        let msg = err_text("$MeshFormat\n4.1 1 8\n\u{1}\u{0}\u{0}\u{0}\n$EndMeshFormat\n");
        assert!(
            msg.contains("m.msh:2: binary .msh is not supported; re-export as ASCII"),
            "{msg}"
        );
        let msg = err_text("$MeshFormat\n4 0 8\n$EndMeshFormat\n");
        assert!(
            msg.contains("m.msh:2: MSH version 4 is not supported"),
            "{msg}"
        );
        let msg = err_text("solid cube\n");
        assert!(msg.contains("m.msh:1: expected $MeshFormat"), "{msg}");
    }

    #[test]
    fn unknown_node_tag_names_the_element_line() {
        let msg = err_text(&MSH41.replace("3 20 30 40 50 11", "3 20 30 40 60 11"));
        assert!(
            msg.contains("m.msh:29: element 3 references node 60, which is not in $Nodes"),
            "{msg}"
        );
        let msg = err_text(&MSH22.replace("4 4 2 1 1 2 3 7 9", "4 4 2 1 1 2 3 7 8"));
        assert!(
            msg.contains("m.msh:21: element 4 references node 8"),
            "{msg}"
        );
    }

    #[test]
    fn fewer_nodes_than_announced_names_the_end_marker_line() {
        let msg = err_text(&MSH22.replace("9 1 1 1\n", ""));
        assert!(
            msg.contains("m.msh:14: expected a node line, found \"$EndNodes\""),
            "{msg}"
        );
        assert!(msg.contains("announces 5 nodes, only 4 came"), "{msg}");
        let msg = err_text(&MSH41.replace("2 5 10 50", "2 4 10 50"));
        assert!(
            msg.contains("m.msh:9: the header announces 4 nodes, but its blocks hold 5"),
            "{msg}"
        );
        let msg = err_text(&MSH22.replace("\n4\n1 15", "\n3\n1 15"));
        assert!(msg.contains("m.msh:21: expected $EndElements"), "{msg}");
    }

    #[test]
    fn truncated_and_non_numeric_input_name_lines() {
        let cut = MSH41.find("$EndNodes").unwrap_or(0);
        let msg = err_text(&MSH41[..cut]);
        assert!(
            msg.contains("m.msh:21: unexpected end of file: expected $EndNodes"),
            "{msg}"
        );
        let msg = err_text(&MSH41.replace("1 1 1\n", "1 one 1\n"));
        assert!(
            msg.contains("m.msh:21: expected a y coordinate, found \"one\""),
            "{msg}"
        );
        let msg = err_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Comments\nhello\n");
        assert!(
            msg.contains("m.msh:5: unexpected end of file: expected $EndComments"),
            "{msg}"
        );
        let msg = err_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
        assert!(
            msg.contains("m.msh:3: unexpected end of file: expected a $Nodes section"),
            "{msg}"
        );
        let msg = err_text("");
        assert!(msg.contains("m.msh:0: the file is empty"), "{msg}");
    }

    #[test]
    fn duplicate_tags_and_misplaced_sections_are_errors() {
        let msg = err_text(&MSH22.replace("7 0 0 1", "3 0 0 1"));
        assert!(msg.contains("m.msh:13: node tag 3 appears twice"), "{msg}");
        let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Elements\n0\n$EndElements\n";
        assert!(err_text(text).contains("m.msh:4: $Elements comes before $Nodes"));
    }

    proptest::proptest! {
        #[test]
        fn truncations_and_noise_never_panic(
            cut in 0usize..1000,
            noise in "[0-9 .$a-zA-Z\n-]{0,300}",
        ) {
            for sample in [MSH41, MSH22] {
                let _ = msh(&sample[..cut.min(sample.len())]);
            }
            let _ = msh(&noise);
            let _ = msh(&format!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n{noise}"));
            let _ = msh(&format!("{}{noise}", &MSH22[..MSH22.find("$Elements").unwrap_or(0)]));
        }
    }
}
