//! Progress bars: shown on a terminal, hidden with `--quiet` or when stderr is not a TTY.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Output policy and scene budgets shared by every subcommand.
pub struct Ctx {
    /// Draw progress bars.
    pub show_progress: bool,
    /// The budgets every scene is loaded within (`--max-triangles`, `--max-scene-bytes`).
    pub limits: dualsplit_scene::Limits,
}

impl Ctx {
    /// Progress is shown unless `quiet` or stderr is not a terminal; default scene budgets.
    pub fn new(quiet: bool) -> Self {
        Self {
            show_progress: !quiet && std::io::stderr().is_terminal(),
            limits: dualsplit_scene::Limits::default(),
        }
    }

    /// A bar over `len` units with a message and an ETA.
    pub fn bar(&self, len: u64, msg: impl Into<String>) -> ProgressBar {
        let pb = if self.show_progress {
            ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr())
        } else {
            ProgressBar::hidden()
        };
        pb.set_style(
            ProgressStyle::with_template("{msg:>24} [{bar:40}] {pos}/{len} ({eta} left)")
                .expect("valid template")
                .progress_chars("=> "),
        );
        pb.set_message(msg.into());
        pb
    }

    /// A spinner for work of unknown length.
    pub fn spinner(&self, msg: impl Into<String>) -> ProgressBar {
        let pb = if self.show_progress {
            ProgressBar::new_spinner()
        } else {
            ProgressBar::hidden()
        };
        pb.set_message(msg.into());
        if self.show_progress {
            pb.enable_steady_tick(std::time::Duration::from_millis(120));
        }
        pb
    }
}
