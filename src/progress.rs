//! Progress output: a bar on a terminal, a plain line every second of simulated time otherwise.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// Reports frame progress to stderr.
pub struct Progress {
    bar: Option<ProgressBar>,
    total: u64,
    every: u64,
}

impl Progress {
    /// Progress over `total` frames; plain lines every `every` frames when not a TTY.
    pub fn new(total: u64, every: u64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::new(total);
            if let Ok(style) = ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {pos}/{len} frames  {msg}",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            b
        });
        Progress {
            bar,
            total,
            every: every.max(1),
        }
    }

    /// Frame `frame` (0-based) finished; `msg` summarises it.
    pub fn frame(&self, frame: u64, msg: impl FnOnce() -> String) {
        match &self.bar {
            Some(b) => {
                b.set_position(frame + 1);
                if frame % 10 == 0 {
                    b.set_message(msg());
                }
            }
            None => {
                if (frame + 1) % self.every == 0 || frame + 1 == self.total {
                    eprintln!("frame {}/{}  {}", frame + 1, self.total, msg());
                }
            }
        }
    }

    /// Close the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish();
        }
    }
}
