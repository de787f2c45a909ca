//! Where the XR session steps the solver: on its own thread paced to real time (the
//! display never waits for it), or inside each display frame (the old lockstep loop,
//! deterministic for a headset on a virtual clock).

use anyhow::{Result, bail};
use clap::ValueEnum;

/// What `incise xr --sim` asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum SimChoice {
    /// A thread, unless the session is an exercise or runs on a simulated headset's
    /// virtual clock (then in the frame).
    #[default]
    Auto,
    /// The simulation thread.
    Thread,
    /// Inside each display frame.
    InFrame,
}

/// Where the solver runs in a session.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimMode {
    /// On its own thread, fixed-dt frames paced to real time; each display frame renders
    /// the latest completed state.
    Thread,
    /// Inside the display frame, by the frame pacer (the display waits for it).
    InFrame,
}

impl SimMode {
    /// The name written to `xr_report.json`.
    pub fn name(self) -> &'static str {
        match self {
            SimMode::Thread => "thread",
            SimMode::InFrame => "in-frame",
        }
    }
}

/// The session's mode for `choice`, and the sentence saying why. `exercise`: an
/// exercise session (scored from the frame loop, so in the frame for now);
/// `virtual_clock`: a simulated headset whose display times do not follow the wall clock
/// (a thread paced to real time would not keep its display times).
pub fn resolve(
    choice: SimChoice,
    exercise: bool,
    virtual_clock: bool,
) -> Result<(SimMode, String)> {
    Ok(match choice {
        SimChoice::Thread if exercise => bail!(
            "--sim thread: exercise sessions step the solver in the frame loop (their scoring \
             reads the body every frame); use --sim in-frame or leave --sim out"
        ),
        SimChoice::Thread => (SimMode::Thread, "--sim thread".into()),
        SimChoice::InFrame => (SimMode::InFrame, "--sim in-frame".into()),
        SimChoice::Auto if exercise => (
            SimMode::InFrame,
            "an exercise session steps the solver in the frame loop".into(),
        ),
        SimChoice::Auto if virtual_clock => (
            SimMode::InFrame,
            "the simulated headset's virtual clock is not real time (a script with \
             realtime: true gets the thread)"
                .into(),
        ),
        SimChoice::Auto => (
            SimMode::Thread,
            "the default: the display never waits for the solver".into(),
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_thread_is_the_default_but_for_exercises_and_virtual_clocks() {
        let mode = |c, e, v| resolve(c, e, v).unwrap().0;
        assert_eq!(mode(SimChoice::Auto, false, false), SimMode::Thread);
        assert_eq!(mode(SimChoice::Auto, true, false), SimMode::InFrame);
        assert_eq!(mode(SimChoice::Auto, false, true), SimMode::InFrame);
        assert_eq!(mode(SimChoice::Thread, false, true), SimMode::Thread);
        assert_eq!(mode(SimChoice::InFrame, false, false), SimMode::InFrame);
        let e = resolve(SimChoice::Thread, true, false).unwrap_err();
        assert!(e.to_string().contains("exercise"), "{e}");
    }
}
