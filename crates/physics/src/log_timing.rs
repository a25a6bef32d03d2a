//! A real logger's timing: rows written a little early or late (jitter), dropped, or missing over
//! a gap. Each row is still logged at a control step and stamped with that step's exact time:
//! each sample's time is exact, the spacing is not.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::readable;

/// The largest `dropped_fraction` accepted.
pub const MAX_DROPPED_FRACTION: f64 = 0.5;

/// The ChaCha stream of the timing draws: the flight's noise is stream 0 of the same seed, so
/// adding a log timing leaves the flight itself unchanged.
const TIMING_STREAM: u64 = 0x6c6f_675f_7469_6d65; // "log_time"

/// How the rows of a simulated log are spaced. Times are counted from the first row (`t = 0`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LogTiming {
    /// Each row is logged at the control step nearest to its nominal time plus a uniform random
    /// offset in `[−jitter_s, jitter_s]`, s (below half a log period, so rows stay in order).
    pub jitter_s: f64,
    /// The probability that a row is dropped (at most [`MAX_DROPPED_FRACTION`]).
    pub dropped_fraction: f64,
    /// `[start_s, length_s]` each: no row is logged in `[start_s, start_s + length_s)`.
    pub gaps: Vec<[f64; 2]>,
}

impl LogTiming {
    /// Checks the numbers against the log rate and the recorded duration; the error names the
    /// field (without the `log_timing.` prefix).
    pub fn validate(&self, log_rate_hz: f64, duration_s: f64) -> Result<(), (String, String)> {
        let half_period = 0.5 / log_rate_hz;
        if !(self.jitter_s.is_finite() && self.jitter_s >= 0.0 && self.jitter_s < half_period) {
            return Err((
                "jitter_s".into(),
                format!(
                    "must be at least 0 and below half a log period ({} s, so that rows stay in order), found {}",
                    readable(half_period),
                    readable(self.jitter_s)
                ),
            ));
        }
        let dropped = self.dropped_fraction;
        if !(dropped.is_finite() && (0.0..=MAX_DROPPED_FRACTION).contains(&dropped)) {
            return Err((
                "dropped_fraction".into(),
                format!(
                    "a probability, must be between 0 and {MAX_DROPPED_FRACTION}, found {}",
                    readable(dropped)
                ),
            ));
        }
        for (index, &[start, length]) in self.gaps.iter().enumerate() {
            if !(start.is_finite()
                && length.is_finite()
                && start >= 0.0
                && length > 0.0
                && start + length <= duration_s)
            {
                return Err((
                    format!("gaps[{index}]"),
                    format!(
                        "must be [start_s, length_s] with start_s ≥ 0, length_s > 0 and start_s + length_s ≤ duration_s ({}), found [{}, {}]",
                        readable(duration_s),
                        readable(start),
                        readable(length)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The control step of each logged row, counted from the first row's nominal step, strictly
    /// increasing. Row `k` of `rows` is due at step `k · per_row`; its offset and whether it is
    /// dropped are drawn for every row, in order, from the seed's own stream (so the jitter does
    /// not depend on the dropped fraction, nor either on the gaps). A step is kept inside the
    /// recording `[0, (rows − 1) · per_row]` and after the previous row's (rounding to the nearest
    /// step may bring two rows together when `per_row` is even).
    pub(crate) fn row_steps(
        &self,
        rows: usize,
        per_row: usize,
        controller_rate_hz: f64,
        seed: u64,
    ) -> Vec<usize> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(TIMING_STREAM);
        let last = (rows.saturating_sub(1) * per_row) as f64;
        let mut steps = Vec::with_capacity(rows);
        let mut next_free = 0.0_f64;
        for k in 0..rows {
            let offset = self.jitter_s * (2.0 * rng.random::<f64>() - 1.0);
            let dropped = rng.random::<f64>() < self.dropped_fraction;
            let nominal = (k * per_row) as f64 + offset * controller_rate_hz;
            let step = nominal.round().max(next_free).min(last);
            next_free = step + 1.0;
            let t = step / controller_rate_hz;
            let in_gap = self
                .gaps
                .iter()
                .any(|&[start, length]| (start..start + length).contains(&t));
            if !dropped && !in_gap {
                steps.push(step as usize);
            }
        }
        steps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(jitter_s: f64, dropped_fraction: f64, gaps: Vec<[f64; 2]>) -> LogTiming {
        LogTiming {
            jitter_s,
            dropped_fraction,
            gaps,
        }
    }

    #[test]
    fn without_jitter_drops_or_gaps_the_rows_are_evenly_spaced() {
        let steps = LogTiming::default().row_steps(301, 10, 500.0, 7);
        assert_eq!(steps, (0..301).map(|k| k * 10).collect::<Vec<_>>());
    }

    #[test]
    fn jittered_rows_stay_within_the_jitter_and_in_order() {
        // Just below half a log period: with an even number of steps per row, two rows may round
        // to the same step before the order is kept.
        for per_row in [2, 3, 10] {
            let jitter = 0.499 / 500.0 * per_row as f64;
            let steps = timing(jitter, 0.0, Vec::new()).row_steps(2000, per_row, 500.0, 3);
            assert_eq!(steps.len(), 2000);
            assert!(steps.windows(2).all(|w| w[1] > w[0]), "{per_row}");
            let reach = (jitter * 500.0).round() as i64;
            let moved: Vec<i64> = steps
                .iter()
                .enumerate()
                .map(|(k, &s)| s as i64 - (k * per_row) as i64)
                .collect();
            assert!(moved.iter().all(|m| m.abs() <= reach), "{per_row}");
            assert!(moved.iter().any(|&m| m != 0), "{per_row}");
            assert!(*steps.last().unwrap() <= 1999 * per_row);
        }
    }

    #[test]
    fn drops_are_independent_of_the_jitter_and_jitter_of_the_drops() {
        let jittered = timing(0.004, 0.0, Vec::new()).row_steps(5000, 10, 500.0, 11);
        let both = timing(0.004, 0.2, Vec::new()).row_steps(5000, 10, 500.0, 11);
        let dropped = timing(0.0, 0.2, Vec::new()).row_steps(5000, 10, 500.0, 11);
        // The same rows are dropped with and without jitter, and the rows kept keep their steps.
        assert_eq!(both.len(), dropped.len());
        assert!(both.iter().all(|s| jittered.binary_search(s).is_ok()));
        let fraction = 1.0 - dropped.len() as f64 / 5000.0;
        assert!((fraction - 0.2).abs() < 0.02, "{fraction}");
        // Another seed, other draws.
        assert_ne!(
            timing(0.004, 0.2, Vec::new()).row_steps(5000, 10, 500.0, 12),
            both
        );
    }

    #[test]
    fn no_row_is_logged_in_a_gap() {
        let steps = timing(0.004, 0.1, vec![[2.0, 0.5], [5.0, 1.0]]).row_steps(501, 10, 500.0, 5);
        let times: Vec<f64> = steps.iter().map(|&s| s as f64 / 500.0).collect();
        assert!(
            times
                .iter()
                .all(|t| !(2.0..2.5).contains(t) && !(5.0..6.0).contains(t))
        );
        assert!(times.iter().any(|t| (1.9..2.0).contains(t)));
        assert!(times.iter().any(|t| (2.5..2.6).contains(t)));
    }

    #[test]
    fn bad_settings_name_their_field() {
        let field = |t: LogTiming| t.validate(50.0, 10.0).unwrap_err().0;
        assert_eq!(field(timing(0.01, 0.0, Vec::new())), "jitter_s");
        assert_eq!(field(timing(-0.001, 0.0, Vec::new())), "jitter_s");
        assert_eq!(field(timing(f64::NAN, 0.0, Vec::new())), "jitter_s");
        assert_eq!(field(timing(0.0, 0.6, Vec::new())), "dropped_fraction");
        assert_eq!(field(timing(0.0, -0.1, Vec::new())), "dropped_fraction");
        assert_eq!(field(timing(0.0, 0.0, vec![[1.0, 0.0]])), "gaps[0]");
        assert_eq!(
            field(timing(0.0, 0.0, vec![[1.0, 1.0], [-1.0, 1.0]])),
            "gaps[1]"
        );
        assert_eq!(field(timing(0.0, 0.0, vec![[9.5, 1.0]])), "gaps[0]");
        assert_eq!(
            field(timing(0.0, 0.0, vec![[f64::INFINITY, 1.0]])),
            "gaps[0]"
        );
        timing(0.00999, MAX_DROPPED_FRACTION, vec![[9.0, 1.0]])
            .validate(50.0, 10.0)
            .unwrap();
    }
}
