//! Which nodes a mass-spring run integrates each frame (PHYSICS.md §2.5, Nakao 2003 §4).

use serde::Deserialize;

/// Localisation of a mass-spring scene's frames around the blade (`model.localisation`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
pub enum Localisation {
    /// Every node every step (no localisation).
    #[default]
    Whole,
    /// The nodes up to level d of the hierarchy from the node nearest the blade (the
    /// paper's fixed levels 4 and 6, Figs. 15–16).
    Level(u32),
    /// The refresh-rate manager: each frame, as many nodes (hence levels) as fit this
    /// many ms of force computation, from the time the last frame took (Fig. 17: 5.6).
    Budget(f64),
}

impl Localisation {
    /// Ok, or why the setting is unusable.
    pub fn validate(&self) -> Result<(), String> {
        match *self {
            Localisation::Budget(ms) if !(ms.is_finite() && ms > 0.0) => {
                Err(format!("Budget({ms}) must be a positive time in ms"))
            }
            _ => Ok(()),
        }
    }

    /// Short name for reports: "whole", "level 4", "budget 5.6 ms".
    pub fn label(&self) -> String {
        match self {
            Localisation::Whole => "whole".into(),
            Localisation::Level(d) => format!("level {d}"),
            Localisation::Budget(ms) => format!("budget {ms} ms"),
        }
    }
}
