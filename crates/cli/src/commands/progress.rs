//! Progress on standard error: the bars, and the observers of the evaluation's runs
//! ([`evaluation::Progress`]). Bars and per-item lines are drawn only on a terminal and without
//! `--quiet` ([`super::Global::show_progress`]); a run's stage times are printed always.

use std::sync::Mutex;
use std::time::Instant;

use evaluation::{Progress, Stage, StageTiming};
use indicatif::{ProgressBar, ProgressStyle};

/// A bar over `cells` cells on standard error, drawn only when `show` (a terminal, not --quiet).
pub fn progress_bar(show: bool, cells: usize, message: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(cells as u64).with_message(message.to_string());
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:32}] {pos}/{len} cells, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    // Drawn (and its clock kept running) from the start: the first cells take seconds.
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// A spinner with a message and the elapsed time on standard error, for work that is not counted
/// in units (the stages of `learn mismatch`), drawn only when `show` (a terminal, not --quiet).
pub fn spinner(show: bool, message: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let spinner = ProgressBar::new_spinner().with_message(message.to_string());
    spinner.set_style(
        ProgressStyle::with_template("{spinner} {msg} ({elapsed})").expect("valid template"),
    );
    spinner.enable_steady_tick(std::time::Duration::from_millis(250));
    spinner
}

/// A bar as an observer: one step per unit of work ([`Progress::advance`]), for a command that
/// draws one bar over one run (`learn meta-train`, its seed spread).
pub struct Bar(pub ProgressBar);

impl Progress for Bar {
    fn advance(&self, _unit: std::fmt::Arguments<'_>) {
        self.0.inc(1);
    }
}

/// `learn reproduce`'s observer: a bar over the units of a stage that counts them (when `show`),
/// and each stage's wall time as it ends.
pub struct StageBars {
    show: bool,
    bar: Mutex<Option<ProgressBar>>,
}

impl StageBars {
    pub fn new(show: bool) -> Self {
        Self {
            show,
            bar: Mutex::new(None),
        }
    }

    /// Removes the current stage's bar, if any.
    fn clear(&self) {
        let bar = self.bar.lock().unwrap_or_else(|e| e.into_inner()).take();
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
    }
}

impl Progress for StageBars {
    fn stage(&self, stage: &Stage<'_>) {
        self.clear();
        if let (true, Some(units)) = (self.show, stage.units) {
            let bar = progress_bar(true, units.total, units.label);
            *self.bar.lock().unwrap_or_else(|e| e.into_inner()) = Some(bar);
        }
    }

    fn advance(&self, _unit: std::fmt::Arguments<'_>) {
        let bar = self.bar.lock().unwrap_or_else(|e| e.into_inner()).clone();
        if let Some(bar) = bar {
            bar.inc(1);
        }
    }

    fn finish(&self, timing: &StageTiming) {
        self.clear();
        note!("{:>7.2} s  {}", timing.seconds, timing.stage);
    }
}

impl Drop for StageBars {
    /// A stage that failed leaves no bar behind.
    fn drop(&mut self) {
        self.clear();
    }
}

/// `learn ablations`' observer: a line per finished unit (a work item), with the time since
/// `start`, when `show`.
pub struct ItemLines {
    pub show: bool,
    pub start: Instant,
}

impl Progress for ItemLines {
    fn advance(&self, unit: std::fmt::Arguments<'_>) {
        if self.show {
            note!("{:>7.1} s  {unit}", self.start.elapsed().as_secs_f64());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hidden_bar_counts_every_unit_of_its_stage_and_is_gone_when_it_ends() {
        let observer = StageBars {
            show: false,
            bar: Mutex::new(None),
        };
        observer.stage(&Stage::counting("work", "work", 3));
        assert!(observer.bar.lock().unwrap().is_none(), "hidden: no bar");
        // A bar as a terminal would get it, hidden here (standard error is not a terminal).
        *observer.bar.lock().unwrap() = Some(ProgressBar::hidden());
        std::thread::scope(|scope| {
            for _ in 0..3 {
                scope.spawn(|| observer.advance(format_args!("unit")));
            }
        });
        let position = observer
            .bar
            .lock()
            .unwrap()
            .as_ref()
            .map(ProgressBar::position);
        assert_eq!(position, Some(3));
        observer.finish(&StageTiming {
            stage: "work".to_string(),
            seconds: 0.5,
        });
        assert!(observer.bar.lock().unwrap().is_none());
    }
}
