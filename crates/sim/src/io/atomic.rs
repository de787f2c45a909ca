//! Atomic file writes: a reader (or a crash) never sees a half-written file.

use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::MeshError;

/// The temporary sibling `path` is first written to: its name with `.tmp` appended.
pub fn temp_path(path: &Path) -> PathBuf {
    let mut name = OsString::from(path.as_os_str());
    name.push(".tmp");
    PathBuf::from(name)
}

/// Write `bytes` to `path` atomically: write and flush a temporary sibling
/// (`<name>.tmp`), then rename it over `path`. On failure the temporary file is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), MeshError> {
    let tmp = temp_path(path);
    let io_error = |path: &Path, source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    };
    let written = std::fs::File::create(&tmp).and_then(|mut file| {
        file.write_all(bytes)?;
        // Data on disk before the rename, so that even a power loss leaves old or new.
        file.sync_all()
    });
    if let Err(source) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_error(&tmp, source));
    }
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        io_error(path, source)
    })
}

#[cfg(test)]
mod tests {
    use super::super::format_checks::scratch;
    use super::*;

    #[test]
    fn replaces_file_and_leaves_no_temp() {
        let dir = scratch("atomic-replace");
        let path = dir.join("frame.vtu");
        write_atomic(&path, b"old").expect("first write");
        write_atomic(&path, b"new contents").expect("second write");
        assert_eq!(std::fs::read(&path).expect("read"), b"new contents");
        assert_eq!(temp_path(&path), dir.join("frame.vtu.tmp"));
        assert!(!temp_path(&path).exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn missing_directory_is_an_io_error_naming_the_file() {
        let dir = scratch("atomic-missing");
        let path = dir.join("no/such/dir/out.vtk");
        let err = write_atomic(&path, b"x").expect_err("no directory");
        assert!(matches!(err, MeshError::Io { .. }));
        assert!(err.to_string().contains("out.vtk.tmp"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
