//! The local results history (`results/history.jsonl`): one JSON line per scored attempt,
//! appended without ever rewriting earlier lines, and the table `incise results` prints.

use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;
use std::time::{SystemTime, UNIX_EPOCH};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::provenance::civil_from_days;

/// One attempt in the history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryEntry {
    /// When it was scored, UTC (`YYYY-MM-DDTHH:MM:SSZ`).
    pub time: String,
    /// Exercise name.
    pub exercise: String,
    /// Stroke file.
    pub stroke: String,
    /// Overall score, 0..100.
    pub score: f64,
    /// Whether every pass condition held.
    pub passed: bool,
    /// Fraction of the plan cut.
    pub completion: f64,
    /// Mean deviation of the trace from the plan, m.
    pub mean_deviation: Option<f64>,
    /// Mean depth error, m.
    pub mean_depth_error: Option<f64>,
    /// Collateral volume, m³.
    pub collateral_volume: f64,
    /// Largest blade force, N.
    pub max_force: f64,
    /// Blade engagements.
    pub strokes: usize,
    /// First to last contact, s.
    pub duration: f64,
    /// The attempt's result.json.
    pub result: String,
}

/// Append `entry` as one line of `path` (folders created). The line goes out in a single
/// `write` on a file opened for appending, so concurrent writers cannot interleave
/// inside it and earlier lines are never rewritten; a last line left without its newline
/// (an interrupted writer) is closed first so the new line stands on its own.
pub fn append(path: &Path, entry: &HistoryEntry) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .read(true)
        .open(path)
        .with_context(|| format!("opening {}", path.display()))?;
    let len = file.metadata()?.len();
    let mut line = String::new();
    if len > 0 {
        let mut last = [0u8];
        file.seek(SeekFrom::Start(len - 1))?;
        file.read_exact(&mut last)?;
        if last[0] != b'\n' {
            line.push('\n');
        }
    }
    line.push_str(&serde_json::to_string(entry)?);
    line.push('\n');
    file.write_all(line.as_bytes())
        .with_context(|| format!("appending to {}", path.display()))
}

/// Every entry of the history file; a line that is not an entry is an error naming it.
pub fn read(path: &Path) -> Result<Vec<HistoryEntry>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the results history {}", path.display()))?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str(l).with_context(|| format!("{}:{}", path.display(), i + 1))
        })
        .collect()
}

/// The history as a text table, oldest first.
pub fn table(entries: &[HistoryEntry]) -> String {
    let mm = |v: Option<f64>| v.map_or("-".into(), |x| format!("{:.1}", x * 1e3));
    let mut out = format!(
        "{:<20} {:<22} {:>5} {:<4} {:>6} {:>7} {:>7} {:>8} {:>6} {:>7} {:>6}\n",
        "time (UTC)",
        "exercise",
        "score",
        "pass",
        "cut %",
        "dev mm",
        "depth±",
        "coll mm³",
        "F max",
        "strokes",
        "time s"
    );
    for e in entries {
        out.push_str(&format!(
            "{:<20} {:<22} {:>5.0} {:<4} {:>6.0} {:>7} {:>7} {:>8.1} {:>6.2} {:>7} {:>6.2}\n",
            e.time,
            e.exercise,
            e.score,
            if e.passed { "yes" } else { "no" },
            e.completion * 100.0,
            mm(e.mean_deviation),
            mm(e.mean_depth_error),
            e.collateral_volume * 1e9,
            e.max_force,
            e.strokes,
            e.duration
        ));
    }
    out
}

/// Now as `YYYY-MM-DDTHH:MM:SSZ` (UTC).
pub fn utc_now() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    utc_string(secs)
}

/// Seconds since 1970 as `YYYY-MM-DDTHH:MM:SSZ`.
fn utc_string(secs: u64) -> String {
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    let rem = secs % 86_400;
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(score: f64) -> HistoryEntry {
        HistoryEntry {
            time: utc_string(0),
            exercise: "e".into(),
            stroke: "s.ron".into(),
            score,
            passed: score > 50.0,
            completion: 1.0,
            mean_deviation: Some(0.001),
            mean_depth_error: None,
            collateral_volume: 0.0,
            max_force: 0.5,
            strokes: 1,
            duration: 1.0,
            result: "r.json".into(),
        }
    }

    #[test]
    fn dates_are_civil_utc() {
        assert_eq!(utc_string(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_string(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_string(1_795_441_530), "2026-11-23T13:45:30Z");
    }

    #[test]
    fn appends_keep_earlier_lines_and_close_a_torn_one() {
        let dir = std::env::temp_dir().join(format!("incise-history-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("results/history.jsonl");
        append(&path, &entry(90.0)).unwrap();
        append(&path, &entry(40.0)).unwrap();
        assert_eq!(read(&path).unwrap(), vec![entry(90.0), entry(40.0)]);
        // An interrupted writer left half a line: the next append starts a new line and
        // reading names the broken one.
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        f.write_all(b"{\"time\":").unwrap();
        append(&path, &entry(70.0)).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().count(), 4);
        let err = format!("{:#}", read(&path).unwrap_err());
        assert!(err.contains("history.jsonl:3"), "{err}");
        let table = table(&[entry(90.0), entry(40.0)]);
        assert_eq!(table.lines().count(), 3);
        assert!(table.contains("yes") && table.contains("no"), "{table}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
