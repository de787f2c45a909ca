//! Wavefront `.obj` triangle surfaces: reader and writer.
//!
//! The reader takes `v x y z [w]` and `f` statements (`a`, `a/b`, `a//c`, `a/b/c` forms,
//! negative indices relative to the vertices so far); polygons are fan-triangulated and
//! every other statement (`vn`, `vt`, `o`, `g`, `s`, `usemtl`, `mtllib`, ...) is ignored.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use super::atomic::write_atomic;
use super::text::{Cursor, Fields, quote};
use crate::{MeshError, TriSurface};

/// Parse an OBJ text into a triangle surface; `origin` names it in errors.
pub fn parse_obj(text: &str, origin: &Path) -> Result<TriSurface, MeshError> {
    let mut c = Cursor::new(text, origin, Some('#'));
    let mut surface = TriSurface::default();
    // Line of each triangle, to name it when a forward index turns out to be missing.
    let mut triangle_lines = Vec::new();
    let mut corners = Vec::new();
    while let Some(mut line) = c.next_line() {
        match line.next_str("a statement")? {
            "v" => {
                let x = line.next("an x coordinate")?;
                let y = line.next("a y coordinate")?;
                let z = line.next("a z coordinate")?;
                surface.positions.push(Vec3::new(x, y, z));
            }
            "f" => {
                corners.clear();
                for token in line.rest() {
                    corners.push(vertex_index(&line, token, surface.positions.len())?);
                }
                if corners.len() < 3 {
                    return Err(line.error(format!(
                        "a face needs at least 3 vertices, found {}",
                        corners.len()
                    )));
                }
                for k in 1..corners.len() - 1 {
                    surface
                        .triangles
                        .push([corners[0], corners[k], corners[k + 1]]);
                    triangle_lines.push(line.line());
                }
            }
            _ => {}
        }
    }
    if surface.triangles.is_empty() {
        return Err(c.eof_error("at least one face (an f statement)"));
    }
    let count = surface.positions.len();
    for (tri, &line) in surface.triangles.iter().zip(&triangle_lines) {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= count) {
            return Err(c.error(
                line,
                format!(
                    "face references vertex {}, but the file has {count} vertices",
                    v as u64 + 1
                ),
            ));
        }
    }
    Ok(surface)
}

/// Write `surface` as OBJ (`v` lines, then 1-based `f` lines), atomically.
pub fn write_obj(path: &Path, surface: &TriSurface) -> Result<(), MeshError> {
    let count = surface.positions.len();
    for (t, tri) in surface.triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= count) {
            return Err(MeshError::Io {
                path: path.to_path_buf(),
                source: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("triangle {t} references vertex {v}, but there are {count}"),
                ),
            });
        }
    }
    let mut s = String::with_capacity(32 * (count + surface.triangles.len()) + 64);
    let _ = writeln!(
        s,
        "# written by incise: {count} vertices, {} triangles",
        surface.triangles.len()
    );
    for p in &surface.positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in &surface.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    write_atomic(path, s.as_bytes())
}

/// The 0-based vertex index of one `f` corner (`a`, `a/b`, `a//c`, `a/b/c`); negative
/// indices count back from the `seen` vertices read so far.
fn vertex_index(line: &Fields<'_>, token: &str, seen: usize) -> Result<u32, MeshError> {
    let head = token.split('/').next().unwrap_or(token);
    let index: i64 = head
        .parse()
        .map_err(|_| line.error(format!("expected a vertex index, found {}", quote(token))))?;
    let resolved = match index {
        0 => return Err(line.error("OBJ vertex indices start at 1, found 0")),
        i if i > 0 => Some(i - 1),
        i => (seen as i64).checked_add(i).filter(|&r| r >= 0),
    };
    resolved.and_then(|r| u32::try_from(r).ok()).ok_or_else(|| {
        line.error(format!(
            "vertex index {index} is out of range: {seen} vertices so far"
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::super::format_checks::scratch;
    use super::*;

    const QUAD_AND_TRI: &str = "\
# a unit square and a triangle
mtllib skin.mtl
o skin
v 0 0 0
v 1 0 0 1.0
v 1 1 0
v 0 1 0
vn 0 0 1
vt 0 0
g front
s off
usemtl tissue
f 1/1/1 2/1/1 3//1 4
v 0.5 0.5 2
f -5 -4 -1
";

    fn obj(text: &str) -> Result<TriSurface, MeshError> {
        parse_obj(text, Path::new("m.obj"))
    }

    fn err_text(text: &str) -> String {
        obj(text).expect_err("input is malformed").to_string()
    }

    #[test]
    fn quad_is_fanned_and_negative_indices_resolve() {
        let s = obj(QUAD_AND_TRI).expect("valid");
        assert_eq!(s.positions.len(), 5);
        assert_eq!(s.positions[4], Vec3::new(0.5, 0.5, 2.0));
        assert_eq!(s.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    }

    #[test]
    fn malformed_faces_name_their_lines() {
        let msg = err_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n");
        assert!(
            msg.contains("m.obj:5: face references vertex 7, but the file has 3"),
            "{msg}"
        );
        let msg = err_text("v 0 0 0\nf 1 2 -3\n");
        assert!(
            msg.contains("m.obj:2: vertex index -3 is out of range"),
            "{msg}"
        );
        let msg = err_text("v 0 0 0\nf 0 1 1\n");
        assert!(
            msg.contains("m.obj:2: OBJ vertex indices start at 1"),
            "{msg}"
        );
        let msg = err_text("v 0 0 0\nv 1 0 0\nf 1 2\n");
        assert!(
            msg.contains("m.obj:3: a face needs at least 3 vertices, found 2"),
            "{msg}"
        );
        let msg = err_text("v 0 0 0\nf 1 a/1 1\n");
        assert!(
            msg.contains("m.obj:2: expected a vertex index, found \"a/1\""),
            "{msg}"
        );
        let msg = err_text("# c\nv 0 zero 0\n");
        assert!(
            msg.contains("m.obj:2: expected a y coordinate, found \"zero\""),
            "{msg}"
        );
        let msg = err_text("v 0 0 0\nv 1 0\n");
        assert!(
            msg.contains("m.obj:2: expected a z coordinate, found the end of the line"),
            "{msg}"
        );
    }

    #[test]
    fn forward_references_are_allowed_but_a_surface_needs_faces() {
        let s = obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").expect("forward references");
        assert_eq!(s.triangles, vec![[0, 1, 2]]);
        let msg = err_text("");
        assert!(
            msg.contains("m.obj:0: the file is empty; expected at least one face"),
            "{msg}"
        );
        let msg = err_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n# no faces\n\n");
        assert!(
            msg.contains("m.obj:5: unexpected end of file: expected at least one face"),
            "{msg}"
        );
    }

    #[test]
    fn write_then_read_round_trips() {
        let dir = scratch("obj");
        let surface = TriSurface {
            positions: vec![
                Vec3::new(0.1, 0.2, 0.3),
                Vec3::new(-1e-6, 3.5, 1e6),
                Vec3::new(7.0, -0.0, 2.0 / 3.0),
            ],
            triangles: vec![[0, 1, 2], [2, 1, 0]],
        };
        let path = dir.join("skin.obj");
        write_obj(&path, &surface).expect("write");
        assert_eq!(super::super::load_surface(&path).expect("read"), surface);
        let bad = TriSurface {
            triangles: vec![[0, 1, 3]],
            ..surface
        };
        let err = write_obj(&path, &bad).expect_err("index 3 of 3");
        assert!(
            err.to_string().contains("triangle 0 references vertex 3"),
            "{err}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    proptest::proptest! {
        #[test]
        fn truncations_and_noise_never_panic(
            cut in 0usize..300,
            noise in "[0-9 ./vf#-]{0,200}",
        ) {
            let _ = obj(&QUAD_AND_TRI[..cut.min(QUAD_AND_TRI.len())]);
            let _ = obj(&noise);
            let _ = obj(&format!("v 0 0 0\nv 1 0 0\n{noise}"));
        }
    }
}
