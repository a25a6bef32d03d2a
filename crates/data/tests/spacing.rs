//! The spacing a flight-log reader requires: `FlightLog::read` only uniform samples (the paper's
//! pipelines difference at a fixed step), `read_spaced(.., Spacing::Any)` a real logger's jitter,
//! dropped rows and gaps; both refuse a time that does not increase.

mod common;

use common::{synthetic_csv, synthetic_log, temp_dir};
use data::{FlightLog, Spacing};

/// A deterministic pseudo-random offset in [−1, 1] for sample `k` (a SplitMix64 hash).
fn offset(k: usize) -> f64 {
    let mut z = (k as u64)
        .wrapping_add(1)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0
}

/// The synthetic 50 Hz log with every time moved by up to ±20 % of the interval.
fn jittered_csv(dir: &std::path::Path) -> std::path::PathBuf {
    let mut log = synthetic_log(200);
    for (k, t) in log.time.iter_mut().enumerate() {
        *t += 0.2 * 0.02 * offset(k);
    }
    let path = dir.join("jittered.csv");
    log.write_csv(&path).unwrap();
    path
}

/// The synthetic 50 Hz log without its data row `dropped`.
fn dropped_row_csv(dir: &std::path::Path, dropped: usize) -> std::path::PathBuf {
    let (_, text) = synthetic_csv(dir, 200);
    let mut lines: Vec<&str> = text.lines().collect();
    lines.remove(dropped + 1);
    let path = dir.join("dropped.csv");
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

#[test]
fn a_jittered_log_is_refused_as_uniform_and_read_with_any_spacing() {
    let dir = temp_dir("spacing-jitter");
    let path = jittered_csv(&dir);
    let message = FlightLog::read(&path).unwrap_err().to_string();
    assert!(
        message.contains("jittered.csv:") && message.contains(":t: sample interval is not uniform"),
        "{message}"
    );
    let log = FlightLog::read_spaced(&path, Spacing::Any).unwrap();
    assert_eq!(log.len(), 200);
    let intervals: Vec<f64> = log.time.windows(2).map(|w| w[1] - w[0]).collect();
    let (low, high) = intervals
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(l, h), &i| (l.min(i), h.max(i)));
    assert!(low < 0.015 && high > 0.025, "{low} {high}");
    // The mean interval is 0.02 s up to the two ends' offsets; the median is near it.
    assert!(
        (log.median_interval() - 0.02).abs() < 0.002,
        "{}",
        log.median_interval()
    );
    let timing = log.sample_timing().unwrap();
    assert!(!timing.uniform);
    assert!(
        timing.p01_ratio < 0.75 && timing.p99_ratio > 1.25,
        "{timing:?}"
    );
    assert_eq!(timing.gaps, 0);
}

#[test]
fn a_dropped_row_is_refused_as_uniform_and_read_with_any_spacing() {
    let dir = temp_dir("spacing-dropped");
    let path = dropped_row_csv(&dir, 100);
    let message = FlightLog::read(&path).unwrap_err().to_string();
    assert!(
        message.contains("dropped.csv:102:t: sample interval is not uniform: worst gap 0.04")
            && message.contains("s against a median of 0.02"),
        "{message}"
    );
    let log = FlightLog::read_spaced(&path, Spacing::Any).unwrap();
    assert_eq!(log.len(), 199);
    assert_eq!(log.time[100], 2.02);
    assert!((log.median_interval() - 0.02).abs() < 1e-12);
    // The mean counts the missing row's interval.
    assert!((log.sample_interval() - 3.98 / 198.0).abs() < 1e-12);
    let timing = log.sample_timing().unwrap();
    assert!(!timing.uniform, "{timing:?}");
    assert!((timing.p01_ratio - 1.0).abs() < 1e-9, "{timing:?}");
    assert!((timing.p99_ratio - 1.0).abs() < 1e-9, "{timing:?}");
    assert_eq!(timing.gaps, 0, "{timing:?}");
    assert!((timing.longest_s - 0.04).abs() < 1e-12, "{timing:?}");
    assert!((timing.longest_at_s - 1.98).abs() < 1e-12, "{timing:?}");
}

#[test]
fn a_gap_is_counted() {
    let mut log = synthetic_log(300);
    for t in log.time.iter_mut().skip(150) {
        *t += 0.5;
    }
    let dir = temp_dir("spacing-gap");
    let path = dir.join("gap.csv");
    log.write_csv(&path).unwrap();
    let log = FlightLog::read_spaced(&path, Spacing::Any).unwrap();
    let timing = log.sample_timing().unwrap();
    assert!(!timing.uniform);
    assert_eq!(timing.gaps, 1);
    assert!((timing.longest_s - 0.52).abs() < 1e-12, "{timing:?}");
    assert!((timing.longest_at_s - 2.98).abs() < 1e-12, "{timing:?}");
    let uniform = synthetic_log(300).sample_timing().unwrap();
    assert!(uniform.uniform && uniform.gaps == 0, "{uniform:?}");
}

#[test]
fn a_time_that_does_not_increase_is_refused_by_both() {
    let mut log = synthetic_log(100);
    log.time[40] = log.time[39];
    let dir = temp_dir("spacing-repeat");
    let path = dir.join("repeat.csv");
    log.write_csv(&path).unwrap();
    for spacing in [Spacing::Uniform, Spacing::Any] {
        let message = FlightLog::read_spaced(&path, spacing)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("repeat.csv:42:t: time is not strictly increasing"),
            "{spacing:?}: {message}"
        );
    }
    assert_eq!(
        FlightLog::read(&path).unwrap_err().to_string(),
        FlightLog::read_spaced(&path, Spacing::Any)
            .unwrap_err()
            .to_string()
    );
}

/// Any spacing still keeps every interval in the plausible range (a time in ms is refused).
#[test]
fn any_spacing_still_refuses_implausible_intervals() {
    let mut log = synthetic_log(100);
    for t in log.time.iter_mut().skip(50) {
        *t += 20.0;
    }
    let dir = temp_dir("spacing-long");
    let path = dir.join("long.csv");
    log.write_csv(&path).unwrap();
    let message = FlightLog::read_spaced(&path, Spacing::Any)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("long.csv:52:t: sample interval 20.02 s is outside the plausible range"),
        "{message}"
    );
}
