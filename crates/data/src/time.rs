//! Checks of the time axis shared by every reader.

use std::path::Path;

use crate::error::{DataError, Result};
use crate::table::file_row;

/// Largest relative deviation of a sample interval from the median interval that still counts as
/// uniform sampling (the Neural-Fly logs deviate by ~1e-12).
pub const DEFAULT_UNIFORM_TOLERANCE: f64 = 0.01;

/// Fails unless `time` has at least two samples, is strictly increasing and uniformly sampled
/// within `tolerance` (relative to the median interval); the error reports the worst gap.
pub fn check_time_axis(path: &Path, time: &[f64], tolerance: f64) -> Result<()> {
    check_time_axis_at(path, time, tolerance, &file_row)
}

/// [`check_time_axis`], with `line(k)` the line of the file that holds sample `k` (for files whose
/// cells span lines).
pub(crate) fn check_time_axis_at(
    path: &Path,
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
                previous: time[k - 1],
                current: time[k],
            });
        }
    }
    let mut gaps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let in_order = gaps.clone();
    gaps.sort_by(f64::total_cmp);
    let median = gaps[gaps.len() / 2];
    // The first of the worst gaps.
    let (index, gap) = in_order
        .iter()
        .enumerate()
        .fold((0, median), |best, (k, &g)| {
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
            gap,
            median,
        });
    }
    Ok(())
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
}
