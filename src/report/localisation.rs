//! The per-loop figures of a mass-spring run as Nakao 2003 tabulates them (Figs. 15–17):
//! the level the localisation reached, the nodes it freed, and the time split of each
//! loop into localise, force, integrate and cut.

use serde::Serialize;

use super::EdgeFrameStats;

/// Time split of one frame's loop, ms.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct LoopSplit {
    /// Nearest node, hierarchy, stopping nodes that left the free set.
    pub localise_ms: f64,
    /// Spring and external forces on the integrated nodes, over the frame's steps.
    pub force_ms: f64,
    /// Velocity and position updates, over the frame's steps.
    pub integrate_ms: f64,
    /// The blade advance: crossings, subdivision, remodelling.
    pub cut_ms: f64,
}

impl LoopSplit {
    /// The four parts added up, ms.
    pub fn total_ms(&self) -> f64 {
        self.localise_ms + self.force_ms + self.integrate_ms + self.cut_ms
    }
}

/// Smallest, mean and largest of a series.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Range {
    /// Smallest value.
    pub min: f64,
    /// Mean.
    pub mean: f64,
    /// Largest value.
    pub max: f64,
}

impl Range {
    /// The range of `values`; `None` when empty.
    pub fn of(values: impl Iterator<Item = f64>) -> Option<Range> {
        let (mut min, mut max, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
        for v in values {
            min = min.min(v);
            max = max.max(v);
            sum += v;
            n += 1;
        }
        (n > 0).then(|| Range {
            min,
            mean: sum / n as f64,
            max,
        })
    }
}

/// One frame's localisation figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSample {
    /// Level reached (`None`: the whole mesh was integrated).
    pub level: Option<u32>,
    /// Nodes integrated.
    pub free_nodes: usize,
    /// Time split.
    pub split: LoopSplit,
}

/// The run's localisation summary for report.json (the paper's table of Figs. 15–17).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LocalisationInfo {
    /// The scene's setting: "whole", "level d" or "budget B ms".
    pub mode: String,
    /// The refresh-rate manager's budget for force + integration per frame, ms.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub budget_ms: Option<f64>,
    /// Frames summarised.
    pub frames: usize,
    /// Levels chosen (absent for whole-mesh runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub level: Option<Range>,
    /// Nodes integrated per frame.
    pub free_nodes: Range,
    /// Localise time per frame, ms.
    pub localise_ms: Range,
    /// Force time per frame, ms.
    pub force_ms: Range,
    /// Integration time per frame, ms.
    pub integrate_ms: Range,
    /// Blade-advance time per frame, ms.
    pub cut_ms: Range,
    /// The four added up per frame, ms.
    pub total_ms: Range,
}

impl LocalisationInfo {
    /// Summarise `samples` of a run in `mode`; `None` when there are none.
    pub fn of(mode: String, budget_ms: Option<f64>, samples: &[LoopSample]) -> Option<Self> {
        let range = |f: &dyn Fn(&LoopSample) -> f64| Range::of(samples.iter().map(f));
        Some(LocalisationInfo {
            mode,
            budget_ms,
            frames: samples.len(),
            level: Range::of(samples.iter().filter_map(|s| s.level.map(f64::from))),
            free_nodes: range(&|s| s.free_nodes as f64)?,
            localise_ms: range(&|s| s.split.localise_ms)?,
            force_ms: range(&|s| s.split.force_ms)?,
            integrate_ms: range(&|s| s.split.integrate_ms)?,
            cut_ms: range(&|s| s.split.cut_ms)?,
            total_ms: range(&|s| s.split.total_ms())?,
        })
    }
}

/// What a live view (the preview's panel, its closing lines) shows of one mass-spring
/// frame's localisation under the scene's `setting` ("whole", "level d", "budget B ms"):
/// the level chosen and the nodes it freed, then the loop's time split. Empty for a frame
/// with no localisation figures (another method's, or a haptic-thread frame).
pub fn live_lines(setting: &str, s: &EdgeFrameStats) -> Vec<String> {
    let Some(free) = s.free_nodes else {
        return Vec::new();
    };
    let chosen = match s.level {
        Some(l) if setting.starts_with("budget") => {
            format!("level {l} (manager, {setting}), {free} nodes free")
        }
        Some(l) => format!("level {l} ({setting}), {free} nodes free"),
        None => format!("whole mesh, {free} nodes"),
    };
    let ms = |v: Option<f64>| v.unwrap_or(0.0);
    vec![
        format!("localisation: {chosen}"),
        format!(
            "loop ms: localise {:.2} · force {:.2} · integrate {:.2} · cut {:.2}",
            ms(s.localise_ms),
            ms(s.force_ms),
            ms(s.integrate_ms),
            ms(s.cut_ms)
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_ranges_cover_the_samples() {
        let s = |level, free, ms| LoopSample {
            level,
            free_nodes: free,
            split: LoopSplit {
                localise_ms: 0.1,
                force_ms: ms,
                integrate_ms: 0.5,
                cut_ms: 0.0,
            },
        };
        let info = LocalisationInfo::of(
            "level 4".into(),
            None,
            &[s(Some(4), 220, 1.0), s(Some(3), 232, 2.0)],
        )
        .unwrap();
        assert_eq!(info.level.unwrap().min, 3.0);
        assert_eq!(info.free_nodes.max, 232.0);
        assert!((info.total_ms.mean - 2.1).abs() < 1e-12);
        assert!(LocalisationInfo::of("whole".into(), None, &[]).is_none());
    }

    #[test]
    fn live_lines_name_the_level_the_manager_chose_and_the_split() {
        let s = EdgeFrameStats {
            level: Some(3),
            free_nodes: Some(512),
            localise_ms: Some(0.25),
            force_ms: Some(4.5),
            integrate_ms: Some(1.0),
            cut_ms: Some(0.125),
            ..EdgeFrameStats::default()
        };
        let lines = live_lines("budget 5.6 ms", &s);
        assert_eq!(
            lines[0],
            "localisation: level 3 (manager, budget 5.6 ms), 512 nodes free"
        );
        assert_eq!(
            lines[1],
            "loop ms: localise 0.25 · force 4.50 · integrate 1.00 · cut 0.12"
        );
        assert_eq!(
            live_lines("level 4", &s)[0],
            "localisation: level 3 (level 4), 512 nodes free"
        );
        assert!(live_lines("whole", &EdgeFrameStats::default()).is_empty());
    }
}
