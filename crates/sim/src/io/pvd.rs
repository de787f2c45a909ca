//! ParaView collection (`.pvd`) files: a time series of snapshot files.

use std::fmt::Write as _;
use std::path::Path;

use super::atomic::write_atomic;
use super::xml::escape_attr;
use crate::MeshError;

/// Write a `.pvd` collection listing `(time, file)` entries, atomically. File names are
/// written as given (ParaView resolves relative names against the `.pvd`'s folder).
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> Result<(), MeshError> {
    if let Some((time, file)) = entries.iter().find(|(t, _)| !t.is_finite()) {
        return Err(MeshError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("the time step {time} of {file:?} is not finite"),
            ),
        });
    }
    let mut s = String::with_capacity(80 * entries.len() + 200);
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    s.push_str("  <Collection>\n");
    for (time, file) in entries {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{time:?}\" group=\"\" part=\"0\" file=\"{}\"/>",
            escape_attr(file)
        );
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    write_atomic(path, s.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::super::format_checks::scratch;
    use super::*;

    #[test]
    fn collection_lists_every_entry_in_order() {
        let dir = scratch("pvd");
        let path = dir.join("run.pvd");
        let entries = vec![
            (0.0, "frames/f_0000.vtu".to_string()),
            (0.0125, "frames/f_0001.vtu".to_string()),
            (1e-7, "a&b \"c\".vtu".to_string()),
        ];
        write_pvd(&path, &entries).expect("write");
        let text = std::fs::read_to_string(&path).expect("read");
        assert!(text.contains("<VTKFile type=\"Collection\""));
        let lines: Vec<&str> = text.lines().filter(|l| l.contains("<DataSet")).collect();
        assert_eq!(lines.len(), 3);
        assert!(
            lines[0].contains("timestep=\"0.0\"")
                && lines[0].contains("file=\"frames/f_0000.vtu\"")
        );
        assert!(lines[1].contains("timestep=\"0.0125\""));
        assert!(lines[2].contains("timestep=\"1e-7\""));
        assert!(lines[2].contains("file=\"a&amp;b &quot;c&quot;.vtu\""));
        assert!(!dir.join("run.pvd.tmp").exists());
        let err = write_pvd(&path, &[(f64::NAN, "x.vtu".into())]).expect_err("NaN time");
        assert!(err.to_string().contains("is not finite"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
