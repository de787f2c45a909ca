//! Mesh file formats: readers return coordinates as in the file, writers write atomically.
//!
//! Tet meshes: TetGen (`.node`/`.ele`/`.face`), Gmsh (`.msh` 2.2 and 4.1 ASCII), legacy
//! VTK (`.vtk` ASCII unstructured grid) and VTK XML (`.vtu` ASCII). Surfaces: Wavefront
//! `.obj`. Simulation output: `.vtu` snapshots collected by a ParaView `.pvd` file.

pub mod atomic;
#[cfg(test)]
mod format_checks;
pub mod gmsh;
pub mod obj;
pub mod pvd;
pub mod tetgen;
pub mod text;
pub mod vtk_cells;
pub mod vtk_legacy;
pub mod vtu;
mod xml;

use std::path::Path;

pub use atomic::write_atomic;
pub use gmsh::parse_msh;
pub use obj::{parse_obj, write_obj};
pub use pvd::write_pvd;
pub use tetgen::{load_tetgen, write_tetgen};
pub use vtk_legacy::{parse_vtk, write_vtk};
pub use vtu::{VtuFrame, parse_vtu, write_vtu};

use crate::{MeshError, RawMesh, TriSurface};
use text::read_text;

/// Read a tet mesh, choosing the format by extension: `.node`/`.ele` (TetGen), `.msh`,
/// `.vtk` or `.vtu`.
pub fn load_mesh(path: &Path) -> Result<RawMesh, MeshError> {
    match extension(path).as_deref() {
        Some("node" | "ele") => load_tetgen(path),
        Some("msh") => parse_msh(&read_text(path)?, path),
        Some("vtk") => parse_vtk(&read_text(path)?, path),
        Some("vtu") => parse_vtu(&read_text(path)?, path),
        _ => Err(MeshError::UnsupportedFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Read a triangle surface; only `.obj` is supported.
pub fn load_surface(path: &Path) -> Result<TriSurface, MeshError> {
    match extension(path).as_deref() {
        Some("obj") => parse_obj(&read_text(path)?, path),
        _ => Err(MeshError::UnsupportedFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// The lower-case extension of `path`, if it has one.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
}

/// Check that every tet index is below `node_count` (writers refuse dangling indices).
fn check_tets(node_count: usize, tets: &[[u32; 4]]) -> Result<(), MeshError> {
    for (tet, t) in tets.iter().enumerate() {
        if let Some(&node) = t.iter().find(|&&v| v as usize >= node_count) {
            return Err(MeshError::NodeIndexOutOfRange {
                tet,
                node: node as u64,
                count: node_count,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::format_checks::scratch;

    #[test]
    fn unknown_extensions_are_unsupported() {
        for name in ["mesh.stl", "mesh", "mesh.node.gz"] {
            let err = load_mesh(Path::new(name)).expect_err("unsupported");
            assert!(
                matches!(err, MeshError::UnsupportedFormat { .. }),
                "{name}: {err}"
            );
        }
        let err = load_surface(Path::new("skin.ply")).expect_err("unsupported");
        assert!(matches!(err, MeshError::UnsupportedFormat { .. }));
    }

    #[test]
    fn missing_file_is_an_io_error_naming_it() {
        let path = std::env::temp_dir().join("incise-io-definitely-missing.MSH");
        let err = load_mesh(&path).expect_err("missing");
        assert!(matches!(err, MeshError::Io { .. }), "{err}");
        assert!(err.to_string().contains("incise-io-definitely-missing.MSH"));
    }

    #[test]
    fn dispatch_reads_each_format_from_disk() {
        let dir = scratch("dispatch");
        let positions = [
            glam::Vec3::ZERO,
            glam::Vec3::X,
            glam::Vec3::Y,
            glam::Vec3::Z,
        ];
        let tets = [[0, 1, 2, 3]];
        write_vtk(&dir.join("a.vtk"), &positions, &tets).expect("vtk");
        let frame = VtuFrame::new(&positions, &tets);
        write_vtu(&dir.join("a.VTU"), &frame).expect("vtu");
        std::fs::write(
            dir.join("a.msh"),
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
             4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n",
        )
        .expect("msh");
        for name in ["a.vtk", "a.VTU", "a.msh"] {
            let raw = load_mesh(&dir.join(name)).expect(name);
            assert_eq!(raw.positions, positions, "{name}");
            assert_eq!(raw.tets, tets, "{name}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn check_tets_names_the_tet() {
        let err = check_tets(4, &[[0, 1, 2, 3], [0, 1, 2, 4]]).expect_err("4 is out");
        assert!(matches!(
            err,
            MeshError::NodeIndexOutOfRange {
                tet: 1,
                node: 4,
                count: 4
            }
        ));
    }
}
