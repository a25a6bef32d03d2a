//! What a run tells its caller while it works: an observer ([`Progress`]) told of each stage as it
//! starts, of each unit of work as it ends (from any worker thread), and of each stage's wall time
//! as it ends, in the manner of argmin's observers. The library draws nothing: a library caller
//! or a test passes [`NoProgress`] (or its own observer); the `learn` binary draws the bars and
//! prints the stage times.

use std::fmt;
use std::time::Instant;

use crate::error::Result;
use crate::summary::StageTiming;

/// A stage of a run, as it starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stage<'a> {
    /// As the run's timings name it, e.g. `SINDy`.
    pub name: &'a str,
    /// The units of work the stage reports through [`Progress::advance`], if it reports any.
    pub units: Option<Units<'a>>,
}

/// The units of work of a [`Stage`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Units<'a> {
    /// How many: the stage calls [`Progress::advance`] this many times when nothing fails.
    pub total: usize,
    /// A short name of the work, for a progress bar, e.g. `LeARN`.
    pub label: &'a str,
}

impl<'a> Stage<'a> {
    /// A stage timed only.
    pub fn timed(name: &'a str) -> Self {
        Self { name, units: None }
    }

    /// A stage that counts `total` units of work, called `label` on a bar.
    pub fn counting(name: &'a str, label: &'a str, total: usize) -> Self {
        Self {
            name,
            units: Some(Units { total, label }),
        }
    }
}

/// A stage named `name`, timed only.
impl<'a> From<&'a str> for Stage<'a> {
    fn from(name: &'a str) -> Self {
        Self::timed(name)
    }
}

/// An observer of a run. Every method does nothing unless implemented; stages do not overlap, and
/// [`Progress::advance`] may be called from several threads at once.
pub trait Progress: Sync {
    /// A stage starts.
    fn stage(&self, stage: &Stage<'_>) {
        let _ = stage;
    }

    /// One unit of the current stage is done; `unit` names it (e.g. a cell, or a work item).
    fn advance(&self, unit: fmt::Arguments<'_>) {
        let _ = unit;
    }

    /// The current stage ended, after `timing.seconds` (not called when the stage fails).
    fn finish(&self, timing: &StageTiming) {
        let _ = timing;
    }
}

/// The observer that observes nothing: for library use and tests.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {}

/// Times a run's stages, telling `progress` of each, and keeps their timings.
pub(crate) struct Stopwatch<'p> {
    progress: &'p dyn Progress,
    timings: Vec<StageTiming>,
}

impl<'p> Stopwatch<'p> {
    pub(crate) fn new(progress: &'p dyn Progress) -> Self {
        Self {
            progress,
            timings: Vec::new(),
        }
    }

    /// Runs `work` as `stage`: the observer is told it starts and, when it succeeds, its time.
    pub(crate) fn time<'s, T>(
        &mut self,
        stage: impl Into<Stage<'s>>,
        work: impl FnOnce() -> Result<T>,
    ) -> Result<T> {
        let stage = stage.into();
        let start = Instant::now();
        self.progress.stage(&stage);
        let value = work()?;
        let timing = StageTiming {
            stage: stage.name.to_string(),
            seconds: start.elapsed().as_secs_f64(),
        };
        self.progress.finish(&timing);
        self.timings.push(timing);
        Ok(value)
    }

    /// The timings of the stages that ended, in order.
    pub(crate) fn timings(self) -> Vec<StageTiming> {
        self.timings
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::EvaluationError;
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Records what it is told.
    #[derive(Default)]
    struct Recorder {
        events: Mutex<Vec<String>>,
        advances: AtomicUsize,
    }

    impl Progress for Recorder {
        fn stage(&self, stage: &Stage<'_>) {
            let units = stage
                .units
                .map_or(String::new(), |u| format!(" ({} {})", u.total, u.label));
            self.events
                .lock()
                .unwrap()
                .push(format!("start {}{units}", stage.name));
        }

        fn advance(&self, unit: fmt::Arguments<'_>) {
            self.advances.fetch_add(1, Ordering::Relaxed);
            self.events.lock().unwrap().push(format!("done {unit}"));
        }

        fn finish(&self, timing: &StageTiming) {
            self.events
                .lock()
                .unwrap()
                .push(format!("end {}", timing.stage));
        }
    }

    #[test]
    fn the_stopwatch_tells_the_observer_each_stage_and_unit_and_keeps_the_timings() {
        let recorder = Recorder::default();
        let mut stopwatch = Stopwatch::new(&recorder);
        stopwatch.time("load", || Ok(())).unwrap();
        let progress: &dyn Progress = &recorder;
        let sum: usize = stopwatch
            .time(Stage::counting("cells", "work", 3), || {
                Ok((0..3)
                    .inspect(|k| progress.advance(format_args!("cell {k}")))
                    .sum())
            })
            .unwrap();
        assert_eq!(sum, 3);
        let failed: Result<()> = stopwatch.time(Stage::timed("broken"), || {
            Err(EvaluationError::Mismatch {
                what: "w".to_string(),
                message: "m".to_string(),
            })
        });
        assert!(failed.is_err());
        assert_eq!(recorder.advances.load(Ordering::Relaxed), 3);
        assert_eq!(
            *recorder.events.lock().unwrap(),
            [
                "start load",
                "end load",
                "start cells (3 work)",
                "done cell 0",
                "done cell 1",
                "done cell 2",
                "end cells",
                "start broken",
            ]
        );
        let stages: Vec<String> = stopwatch.timings().into_iter().map(|t| t.stage).collect();
        assert_eq!(stages, ["load", "cells"]);
    }

    #[test]
    fn no_progress_observes_nothing_and_is_shared_between_threads() {
        let progress: &dyn Progress = &NoProgress;
        std::thread::scope(|scope| {
            for _ in 0..2 {
                scope.spawn(|| {
                    progress.stage(&Stage::counting("s", "s", 1));
                    progress.advance(format_args!("unit"));
                    progress.finish(&StageTiming {
                        stage: "s".to_string(),
                        seconds: 0.0,
                    });
                });
            }
        });
    }
}
