//! Checks of the time axis shared by every reader.

use std::path::Path;

use serde::Serialize;
use statrs::statistics::{Data, OrderStatistics};

use crate::error::{DataError, Result};
use crate::table::file_row;

/// The median of the sample intervals: of an even count the larger middle value (statrs' order
/// statistic n/2 + 1); NaN for none.
pub(crate) fn median_interval(time: &[f64]) -> f64 {
    upper_median(time.windows(2).map(|w| w[1] - w[0]).collect())
}

/// Of an even count the larger middle value (statrs' order statistic n/2 + 1); NaN for none.
fn upper_median(values: Vec<f64>) -> f64 {
    let order = values.len() / 2 + 1;
    Data::new(values).order_statistic(order)
}

/// An interval longer than this many median intervals is a gap.
pub const GAP_INTERVALS: f64 = 3.0;

/// How the samples of a time column are spaced: what a reader of [`Spacing::Any`] lets through.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleTiming {
    pub median_interval_s: f64,
    /// The 1st and the 99th percentile of the intervals, relative to the median (the jitter).
    pub p01_ratio: f64,
    pub p99_ratio: f64,
    /// Whether every interval lies within `uniform_tolerance` of the median (what
    /// [`Spacing::Uniform`] accepts).
    pub uniform: bool,
    /// [`DEFAULT_UNIFORM_TOLERANCE`], relative to the median.
    pub uniform_tolerance: f64,
    /// Intervals longer than `gap_intervals` median intervals.
    pub gaps: usize,
    /// [`GAP_INTERVALS`].
    pub gap_intervals: f64,
    /// The longest interval, and the time of the sample it starts at.
    pub longest_s: f64,
    pub longest_at_s: f64,
}

impl SampleTiming {
    /// The timing of a strictly increasing `time`; `None` under two samples.
    pub(crate) fn of(time: &[f64]) -> Option<Self> {
        let intervals: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
        let longest =
            (0..intervals.len()).max_by(|&a, &b| intervals[a].total_cmp(&intervals[b]))?;
        let median = median_interval(time);
        let mut ratios = Data::new(intervals.iter().map(|i| i / median).collect::<Vec<_>>());
        Some(Self {
            median_interval_s: median,
            p01_ratio: ratios.quantile(0.01),
            p99_ratio: ratios.quantile(0.99),
            uniform: intervals
                .iter()
                .all(|i| (i - median).abs() <= DEFAULT_UNIFORM_TOLERANCE * median),
            uniform_tolerance: DEFAULT_UNIFORM_TOLERANCE,
            gaps: intervals
                .iter()
                .filter(|&&i| i > GAP_INTERVALS * median)
                .count(),
            gap_intervals: GAP_INTERVALS,
            longest_s: intervals[longest],
            longest_at_s: time[longest],
        })
    }
}

/// Largest relative deviation of a sample interval from the median interval that still counts as
/// uniform sampling (the Neural-Fly logs deviate by ~1e-12).
pub const DEFAULT_UNIFORM_TOLERANCE: f64 = 0.01;

/// The spacing of the samples a reader requires of a time column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// Uniform sampling: every interval within [`DEFAULT_UNIFORM_TOLERANCE`] of the median (what
    /// a pipeline that differences at a fixed step needs).
    Uniform,
    /// Any spacing: strictly increasing and every interval within `SAMPLE_INTERVAL_RANGE_S`, with
    /// jitter, dropped samples and gaps allowed (a real logger's time stamps).
    Any,
}

impl Spacing {
    /// The largest relative deviation of an interval from the median that this spacing accepts.
    pub(crate) fn tolerance(self) -> f64 {
        match self {
            Self::Uniform => DEFAULT_UNIFORM_TOLERANCE,
            Self::Any => f64::INFINITY,
        }
    }
}

/// Fails unless `time` (a column named `t`) has at least two samples, is strictly increasing and
/// uniformly sampled within `tolerance` (relative to the median interval); the error reports the
/// worst gap.
pub fn check_time_axis(path: &Path, time: &[f64], tolerance: f64) -> Result<()> {
    check_time_axis_at(path, "t", time, tolerance, &file_row)
}

/// [`check_time_axis`] of the time column named `column`, with `line(k)` the line of the file that
/// holds sample `k` (for files whose cells span lines). Errors name `column`.
pub(crate) fn check_time_axis_at(
    path: &Path,
    column: &str,
    time: &[f64],
    tolerance: f64,
    line: &dyn Fn(usize) -> usize,
) -> Result<()> {
    if time.len() < 2 {
        return Err(DataError::TooShort {
            path: path.to_path_buf(),
            rows: time.len(),
            needed: 2,
        });
    }
    for k in 1..time.len() {
        if time[k] <= time[k - 1] {
            return Err(DataError::TimeNotIncreasing {
                path: path.to_path_buf(),
                row: line(k),
                column: column.to_string(),
                previous: time[k - 1],
                current: time[k],
            });
        }
    }
    let median = median_interval(time);
    // The first of the worst gaps.
    let (index, gap) =
        time.windows(2)
            .map(|w| w[1] - w[0])
            .enumerate()
            .fold((0, median), |best, (k, g)| {
                if (g - median).abs() > (best.1 - median).abs() {
                    (k, g)
                } else {
                    best
                }
            });
    if (gap - median).abs() > tolerance * median {
        return Err(DataError::NonUniformSampling {
            path: path.to_path_buf(),
            row: line(index + 1),
            column: column.to_string(),
            gap,
            median,
        });
    }
    Ok(())
}

/// Fails unless every interval of a strictly increasing `time` (the column named `column`) lies in
/// `[min, max]` seconds; the error names the line of the first sample after an offending interval.
pub(crate) fn check_interval_range(
    path: &Path,
    column: &str,
    time: &[f64],
    (min, max): (f64, f64),
    line: &dyn Fn(usize) -> usize,
) -> Result<()> {
    for k in 1..time.len() {
        let interval = time[k] - time[k - 1];
        if !(min..=max).contains(&interval) {
            return Err(DataError::ImplausibleInterval {
                path: path.to_path_buf(),
                row: line(k),
                column: column.to_string(),
                interval,
                min,
                max,
            });
        }
    }
    Ok(())
}

/// Gaps from which [`StreamedTimeAxis`] takes its reference step.
const REFERENCE_GAPS: usize = 4096;

/// The checks of `check_time_column` on a time column read in blocks, in constant memory:
/// strictly increasing, and every gap within `tolerance` (infinite: any gap) of a reference step, the median of the
/// first `REFERENCE_GAPS` gaps (the whole column's median would need every gap at once). Errors
/// name the line of the row.
pub struct StreamedTimeAxis {
    path: std::path::PathBuf,
    column: String,
    tolerance: f64,
    first: f64,
    last: f64,
    rows: usize,
    reference: Option<f64>,
    smallest_step: f64,
    largest_step: f64,
    /// The first gaps, with the line of the row each ends on, until the reference is known.
    pending: Vec<(usize, f64)>,
}

impl StreamedTimeAxis {
    pub fn new(path: &Path, column: &str, tolerance: f64) -> Self {
        Self {
            path: path.to_path_buf(),
            column: column.to_string(),
            tolerance,
            first: f64::NAN,
            last: f64::NAN,
            rows: 0,
            reference: None,
            smallest_step: f64::INFINITY,
            largest_step: 0.0,
            pending: Vec::new(),
        }
    }

    /// The next values of the column, with the line of the file each row starts on.
    pub fn push(&mut self, values: &[f64], lines: &[usize]) -> Result<()> {
        for (&value, &line) in values.iter().zip(lines) {
            let row = self.rows;
            self.rows += 1;
            if row == 0 {
                (self.first, self.last) = (value, value);
                continue;
            }
            if value <= self.last {
                return Err(DataError::TimeNotIncreasing {
                    path: self.path.clone(),
                    row: line,
                    column: self.column.clone(),
                    previous: self.last,
                    current: value,
                });
            }
            let gap = value - self.last;
            self.last = value;
            self.smallest_step = self.smallest_step.min(gap);
            self.largest_step = self.largest_step.max(gap);
            match self.reference {
                Some(step) => self.check_gap(line, gap, step)?,
                None => {
                    self.pending.push((line, gap));
                    if self.pending.len() == REFERENCE_GAPS {
                        self.settle()?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The smallest and the largest step pushed so far (`None` before the second row).
    pub fn step_range(&self) -> Option<(f64, f64)> {
        (self.rows > 1).then_some((self.smallest_step, self.largest_step))
    }

    /// The number of rows and the mean step `(t_last − t_first) / (rows − 1)`.
    pub fn finish(mut self) -> Result<(usize, f64)> {
        if self.rows < 2 {
            return Err(DataError::TooShort {
                path: self.path.clone(),
                rows: self.rows,
                needed: 2,
            });
        }
        if self.reference.is_none() {
            self.settle()?;
        }
        Ok((self.rows, (self.last - self.first) / (self.rows - 1) as f64))
    }

    fn settle(&mut self) -> Result<()> {
        let step = upper_median(self.pending.iter().map(|p| p.1).collect());
        self.reference = Some(step);
        for (line, gap) in std::mem::take(&mut self.pending) {
            self.check_gap(line, gap, step)?;
        }
        Ok(())
    }

    fn check_gap(&self, line: usize, gap: f64, step: f64) -> Result<()> {
        if (gap - step).abs() > self.tolerance * step {
            return Err(DataError::NonUniformSampling {
                path: self.path.clone(),
                row: line,
                column: self.column.clone(),
                gap,
                median: step,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_axis_passes() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.02).collect();
        check_time_axis(Path::new("f.csv"), &t, DEFAULT_UNIFORM_TOLERANCE).unwrap();
    }

    #[test]
    fn reports_the_worst_gap_and_its_row() {
        let mut t: Vec<f64> = (0..100).map(|k| k as f64 * 0.02).collect();
        for v in t.iter_mut().skip(40) {
            *v += 0.03;
        }
        for v in t.iter_mut().skip(70) {
            *v += 0.01;
        }
        let message = check_time_axis(Path::new("f.csv"), &t, 0.01)
            .unwrap_err()
            .to_string();
        // Sample 40 is data row 40 (0-based), line 42 of the file.
        assert!(message.starts_with("f.csv:42:t:"), "{message}");
        assert!(message.contains("worst gap 0.05"), "{message}");
    }

    #[test]
    fn repeated_time_is_not_increasing() {
        let t = [0.0, 0.02, 0.02, 0.06];
        let message = check_time_axis(Path::new("f.csv"), &t, 0.01)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("f.csv:4:t: time is not strictly increasing"),
            "{message}"
        );
    }

    #[test]
    fn errors_name_the_time_column_they_check() {
        let t = [0.0, 0.02, 0.01, 0.06];
        let message = check_time_axis_at(Path::new("f.csv"), "time", &t, 0.01, &file_row)
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("f.csv:4:time: time is not strictly increasing"),
            "{message}"
        );
        let t = [0.0, 0.02, 0.04, 0.1];
        let message = check_time_axis_at(Path::new("f.csv"), "time", &t, 0.01, &file_row)
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("f.csv:5:time: sample interval is not uniform"),
            "{message}"
        );
    }

    #[test]
    fn intervals_outside_the_range_are_named_compactly() {
        let t: Vec<f64> = (0..5).map(|k| k as f64 * 2e-302).collect();
        let message = check_interval_range(Path::new("f.csv"), "t", &t, (1e-4, 10.0), &file_row)
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            "f.csv:3:t: sample interval 2e-302 s is outside the plausible range [0.0001, 10] s of a flight log (is the time in seconds?)"
        );
        let t = [0.0, 20.0, 40.0];
        let message = check_interval_range(Path::new("f.csv"), "t", &t, (1e-4, 10.0), &file_row)
            .unwrap_err()
            .to_string();
        assert!(message.contains("sample interval 20 s"), "{message}");
        let t: Vec<f64> = (0..5).map(|k| k as f64 * 0.02).collect();
        check_interval_range(Path::new("f.csv"), "t", &t, (1e-4, 10.0), &file_row).unwrap();
    }
}
