//! `incise preview`: the desktop window (winit) with the incise-xr renderer, an egui
//! side panel, orbit/pan/zoom and the mouse scalpel (left-drag cuts, see
//! [`scalpel_input`]), one content for a scene of every method ([`live`]): the body
//! drawn with its own heat map, its script moving the tool until the mouse takes it, the
//! method's live settings where it has them. `--frames N` renders N frames and exits (for
//! tests and scripts), printing what the body did; `--screenshot FILE` saves the
//! window's last frame (also when Escape closes it). `--exercise FILE` opens an exercise
//! ([`PreviewExercise`]): its plan drawn on the tissue, attempts scored live and saved.

mod camera_input;
pub mod display;
mod frame_times;
pub mod hand;
pub mod live;
mod live_actions;
mod options;
mod panel;
pub mod pick;
pub mod scalpel_input;
pub mod scene_list;
mod window_app;
mod window_gpu;

use anyhow::{Result, bail};

use live::Live;
pub use options::{ATTEMPTS_DIR, HISTORY_FILE, PreviewExercise, PreviewOptions};
use window_app::run_window;

/// Open the preview window and run until it is closed (or `--frames` are done); prints
/// what the body did.
pub fn run(opts: PreviewOptions) -> Result<()> {
    if let Some(why) = display::missing_display() {
        bail!("{why}: the preview needs a window; use `incise run` or `incise render` headless");
    }
    let Some(live) = run_window(opts.size, |shell| Live::open(shell, opts))? else {
        return Ok(());
    };
    println!("{}", live.close()?);
    Ok(())
}
