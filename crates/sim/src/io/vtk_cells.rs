//! VTK cells, as the legacy (`.vtk`) and XML (`.vtu`) formats share them: the cell type
//! numbers and names, the cell list as read, and the tets taken from it.

use std::collections::BTreeMap;
use std::path::Path;

use crate::MeshError;

/// VTK cell type of a linear tetrahedron.
pub const VTK_TETRA: u32 = 10;
/// VTK cell type of a quadratic (10-node) tetrahedron; its first four points are corners.
pub const VTK_QUADRATIC_TETRA: u32 = 24;

/// Cells as read: connectivity, and per cell its run in it and the line it starts on.
#[derive(Debug, Default)]
pub(super) struct CellList {
    /// Point indices of all cells, concatenated.
    pub conn: Vec<u32>,
    /// Per cell: (start in `conn`, number of points, 1-based line where it starts).
    pub runs: Vec<(usize, usize, usize)>,
}

/// Human name of a VTK cell type.
pub fn cell_type_name(ty: u32) -> Option<&'static str> {
    Some(match ty {
        1 => "vertex",
        2 => "poly-vertex",
        3 => "line",
        4 => "poly-line",
        5 => "triangle",
        6 => "triangle strip",
        7 => "polygon",
        8 => "pixel",
        9 => "quad",
        10 => "tetra",
        11 => "voxel",
        12 => "hexahedron",
        13 => "wedge",
        14 => "pyramid",
        21 => "quadratic edge",
        22 => "quadratic triangle",
        23 => "quadratic quad",
        24 => "quadratic tetra",
        25 => "quadratic hexahedron",
        _ => return None,
    })
}

/// Tets from cells and their types; other types become one warning per type.
pub(super) fn tets_from_cells(
    cells: &CellList,
    types: &[u32],
    origin: &Path,
) -> Result<(Vec<[u32; 4]>, Vec<String>), MeshError> {
    let mut tets = Vec::with_capacity(cells.runs.len());
    let mut skipped: BTreeMap<u32, u64> = BTreeMap::new();
    for (k, (&(start, len, line), &ty)) in cells.runs.iter().zip(types).enumerate() {
        let need = match ty {
            VTK_TETRA => 4,
            VTK_QUADRATIC_TETRA => 10,
            _ => {
                *skipped.entry(ty).or_default() += 1;
                continue;
            }
        };
        if len != need {
            return Err(MeshError::parse(
                origin,
                line,
                format!("cell {k} has type {ty} ({need} points) but lists {len} points"),
            ));
        }
        let c = &cells.conn[start..start + 4];
        tets.push([c[0], c[1], c[2], c[3]]);
    }
    let warnings = skipped
        .into_iter()
        .map(|(ty, n)| {
            let noun = if n == 1 { "cell" } else { "cells" };
            match cell_type_name(ty) {
                Some(name) => format!("skipped {n} {noun} of VTK type {ty} ({name})"),
                None => format!("skipped {n} {noun} of VTK type {ty}"),
            }
        })
        .collect();
    Ok((tets, warnings))
}
