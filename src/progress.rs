//! The progress bar: this program's one [`Observer`] of the library's long work (hidden when
//! stderr is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};
use robocal_core::{Observer, Stage};

/// A progress bar that shows what the library reports: the stage's words, its steps done and in
/// all (the solver's iteration and its budget while identifying).
pub struct Bar(ProgressBar);

impl Bar {
    /// A bar labelled `msg` until the first report.
    pub fn new(msg: &str) -> Bar {
        let pb = ProgressBar::new(0);
        pb.set_style(
            ProgressStyle::with_template("{msg:>14} [{bar:40}] {pos}/{len} ({elapsed})")
                .expect("valid template")
                .progress_chars("=> "),
        );
        pb.set_message(msg.to_owned());
        Bar(pb)
    }

    /// Shows `msg` for a step of the program's own (no count).
    pub fn note(&self, msg: &str) {
        self.0.set_message(msg.to_owned());
        self.0.set_length(0);
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Observer for Bar {
    fn progress(&self, stage: Stage, done: usize, total: usize) {
        self.0.set_message(stage.describe());
        self.0.set_length(total as u64);
        self.0.set_position(done as u64);
    }
}

/// A spinner for work of unknown length.
pub fn spinner(msg: &str) -> ProgressBar {
    let pb = ProgressBar::new_spinner();
    pb.set_style(
        ProgressStyle::with_template("{spinner} {msg} ({elapsed})").expect("valid template"),
    );
    pb.set_message(msg.to_owned());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}
