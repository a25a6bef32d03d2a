//! The spacing of a CSV flight log's samples in `learn data inspect FLIGHT.csv`: [`SampleTiming`],
//! as the `data` crate's `FlightLog::sample_timing` serialises it (the CLI hands its JSON over;
//! every field is named here, an unknown one is refused), rendered by [`sample_timing_text`].

use serde::{Deserialize, Serialize};

/// How the samples of a log are spaced (see the `data` crate's `SampleTiming`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleTiming {
    pub median_interval_s: f64,
    /// The 1st and the 99th percentile of the intervals, relative to the median.
    pub p01_ratio: f64,
    pub p99_ratio: f64,
    /// Every interval within `uniform_tolerance` (relative) of the median.
    pub uniform: bool,
    pub uniform_tolerance: f64,
    /// Intervals over `gap_intervals` medians.
    pub gaps: usize,
    pub gap_intervals: f64,
    /// The longest interval and the time of the sample it starts at, s.
    pub longest_s: f64,
    pub longest_at_s: f64,
}

/// The `spacing:` line, and for an unevenly spaced log a `gaps:` line, of the inspection: one
/// line for a uniformly sampled log, the median, the jitter and the gaps otherwise.
pub fn sample_timing_text(timing: &SampleTiming) -> String {
    let median = timing.median_interval_s;
    if timing.uniform {
        return format!(
            "spacing:   uniform, every interval within {} % of the median {median:.6} s\n",
            timing.uniform_tolerance * 100.0
        );
    }
    let mut text = format!(
        "spacing:   uneven (readers of uniform samples, as the paper's pipelines, refuse it): median interval {median:.6} s ({:.3} Hz), 1st to 99th percentile {:.3} to {:.3} × the median\n",
        1.0 / median,
        timing.p01_ratio,
        timing.p99_ratio
    );
    let longest = format!(
        "the longest interval {:.6} s ({:.1} × the median) from t = {:.3} s",
        timing.longest_s,
        timing.longest_s / median,
        timing.longest_at_s
    );
    text.push_str(&match timing.gaps {
        0 => format!(
            "gaps:      none over {} × the median; {longest}\n",
            timing.gap_intervals
        ),
        count => format!(
            "gaps:      {count} interval{} over {} × the median; {longest}\n",
            if count == 1 { "" } else { "s" },
            timing.gap_intervals
        ),
    });
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(uniform: bool, gaps: usize) -> SampleTiming {
        SampleTiming {
            median_interval_s: 0.02,
            p01_ratio: 0.8,
            p99_ratio: 1.2,
            uniform,
            uniform_tolerance: 0.01,
            gaps,
            gap_intervals: 3.0,
            longest_s: 0.5,
            longest_at_s: 12.34,
        }
    }

    #[test]
    fn a_uniform_log_takes_one_line_an_uneven_one_says_its_jitter_and_gaps() {
        assert_eq!(
            sample_timing_text(&timing(true, 0)),
            "spacing:   uniform, every interval within 1 % of the median 0.020000 s\n"
        );
        assert_eq!(
            sample_timing_text(&timing(false, 2)),
            "spacing:   uneven (readers of uniform samples, as the paper's pipelines, refuse it): median interval 0.020000 s (50.000 Hz), 1st to 99th percentile 0.800 to 1.200 × the median\n\
             gaps:      2 intervals over 3 × the median; the longest interval 0.500000 s (25.0 × the median) from t = 12.340 s\n"
        );
        assert!(
            sample_timing_text(&timing(false, 0))
                .contains("gaps:      none over 3 × the median; the longest interval 0.500000 s")
        );
        assert!(sample_timing_text(&timing(false, 1)).contains("gaps:      1 interval over"));
    }

    #[test]
    fn an_unknown_field_is_refused() {
        let mut value = serde_json::to_value(timing(true, 0)).unwrap();
        value["extra"] = 1.into();
        assert!(serde_json::from_value::<SampleTiming>(value).is_err());
    }
}
