//! The three simulation methods, by the name reports give them.

use serde::Serialize;

/// The three simulation methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// XPBD Neo-Hookean tets, released where the von Mises stress passes the threshold
    /// (PHYSICS.md §1).
    Xpbd,
    /// Nakao's tension mass-spring cutter (PHYSICS.md §2).
    Nakao,
    /// The three-element rheological body (PHYSICS.md §3).
    Rheology,
}

impl Method {
    /// Whether a headset session shows the heat map from the start: the method's own
    /// quantity (tension, strain) is what a Nakao or rheology session is for; XPBD's
    /// stress overlay is switched on by hand.
    pub fn heat_map_first(self) -> bool {
        self != Method::Xpbd
    }

    /// The name written to report.json's `method`: "xpbd", "nakao" or "rheology".
    pub fn name(self) -> &'static str {
        match self {
            Method::Xpbd => "xpbd",
            Method::Nakao => "nakao",
            Method::Rheology => "rheology",
        }
    }
}
