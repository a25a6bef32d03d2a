//! How often a column really changes. A topic logged at 100 Hz may carry a value that changes at
//! 10 Hz: held (zero-order hold: runs of bit-identical values) or linearly interpolated (samples
//! on the straight line between their neighbours, to rounding). Counting the samples that bring
//! something new tells which (`docs/ulog.md`).

use serde::Serialize;

/// How a column's samples relate to each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnPattern {
    /// Most samples are new values.
    Fresh,
    /// Runs of identical values: the value changes at the effective rate only.
    Held,
    /// Samples between knots lie on the line through their neighbours.
    Interpolated,
    /// One value throughout.
    Constant,
}

/// At most this share of samples new for a column to count as held or interpolated (a value
/// logged at 1.5 times the rate it changes at or more; integer outputs such as PWM repeat by
/// quantisation in up to about a sample in ten).
const NEW_SHARE: f64 = 0.7;

/// Samples of a column, and how many of them bring a new value: changes (the first sample
/// counted) and knots (samples off the line through their neighbours; the ends counted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NewSamples {
    pub samples: usize,
    pub changes: usize,
    pub knots: usize,
}

impl NewSamples {
    /// Counts the samples of `values` at `times` (s, increasing) that bring a new value.
    /// `epsilon` is the relative precision the values were stored with (f32::EPSILON for a float
    /// field).
    pub fn count(times: &[f64], values: &[f64], epsilon: f64) -> Self {
        let n = values.len();
        // Held samples are copies: bit-identical (so NaN repeats too, and -0 differs from 0).
        let changes = usize::from(n > 0)
            + values
                .windows(2)
                .filter(|w| w[0].to_bits() != w[1].to_bits())
                .count();
        let interior = (1..n.saturating_sub(1))
            .filter(|&i| !on_line(&times[i - 1..=i + 1], &values[i - 1..=i + 1], epsilon))
            .count();
        Self {
            samples: n,
            changes,
            knots: n.min(2) + interior,
        }
    }

    /// The counts of two stretches of one column together.
    pub fn and(self, other: Self) -> Self {
        Self {
            samples: self.samples + other.samples,
            changes: self.changes + other.changes,
            knots: self.knots + other.knots,
        }
    }

    /// The column's pattern and its new samples (changes if held, knots if interpolated).
    pub fn pattern(self) -> (ColumnPattern, usize) {
        let n = self.samples as f64;
        if self.samples < 3 {
            (ColumnPattern::Fresh, self.samples)
        } else if self.changes <= 1 {
            (ColumnPattern::Constant, self.changes)
        } else if self.changes as f64 <= NEW_SHARE * n {
            (ColumnPattern::Held, self.changes)
        } else if self.knots as f64 <= NEW_SHARE * n {
            (ColumnPattern::Interpolated, self.knots)
        } else {
            (ColumnPattern::Fresh, self.samples)
        }
    }
}

/// The pattern of `values` sampled at `times` and how many samples bring a new value (see
/// [`NewSamples`]).
pub fn column_pattern(times: &[f64], values: &[f64], epsilon: f64) -> (ColumnPattern, usize) {
    NewSamples::count(times, values, epsilon).pattern()
}

/// Whether the middle of three samples lies on the line through the outer two, to the rounding
/// of the stored precision (two units in the last place). A change too small to tell a line from
/// rounding (under 64 units over the three samples) is not taken for interpolation.
fn on_line(t: &[f64], x: &[f64], epsilon: f64) -> bool {
    let span = t[2] - t[0];
    if span <= 0.0 || !x.iter().all(|v| v.is_finite()) {
        return false;
    }
    let unit = epsilon * x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let line = x[0] + (x[2] - x[0]) * (t[1] - t[0]) / span;
    (x[2] - x[0]).abs() >= 64.0 * unit && (x[1] - line).abs() <= 2.0 * unit
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(n: usize, rate: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 / rate).collect()
    }

    #[test]
    fn a_signal_held_between_updates_changes_at_the_update_rate() {
        let t = times(100, 100.0);
        let x: Vec<f64> = t
            .iter()
            .map(|&t| f64::from(((t * 10.0).floor() as f32).sin()))
            .collect();
        assert_eq!(
            column_pattern(&t, &x, f64::from(f32::EPSILON)),
            (ColumnPattern::Held, 10)
        );
    }

    #[test]
    fn a_signal_interpolated_between_knots_has_its_knots_counted() {
        let t = times(101, 100.0);
        // Knots every 10 samples, values in between on the line, stored as f32.
        let knot = |k: usize| (k as f64 * 0.7).sin() * 5.0;
        let x: Vec<f64> = (0..101)
            .map(|i| {
                let (k, f) = (i / 10, (i % 10) as f64 / 10.0);
                let value = knot(k) + (knot(k + 1) - knot(k)) * f;
                f64::from(value as f32)
            })
            .collect();
        let (pattern, knots) = column_pattern(&t, &x, f64::from(f32::EPSILON));
        assert_eq!(pattern, ColumnPattern::Interpolated);
        assert!((11..=13).contains(&knots), "{knots}");
    }

    #[test]
    fn a_fresh_signal_and_a_constant_are_told_apart() {
        let t = times(50, 100.0);
        let x: Vec<f64> = t
            .iter()
            .map(|&t| (t * 37.0).sin() + (t * 91.0).cos())
            .collect();
        assert_eq!(
            column_pattern(&t, &x, f64::EPSILON),
            (ColumnPattern::Fresh, 50)
        );
        assert_eq!(
            column_pattern(&t, &vec![2.0; 50], f64::EPSILON),
            (ColumnPattern::Constant, 1)
        );
    }

    #[test]
    fn a_slow_signal_near_its_precision_is_not_taken_for_interpolation() {
        // A quaternion component near 1 drifting by about an f32 unit per sample.
        let t = times(200, 20.0);
        let x: Vec<f64> = t
            .iter()
            .map(|&t| f64::from((0.99999 + 2e-6 * (t * 0.9).sin()) as f32))
            .collect();
        assert_ne!(
            column_pattern(&t, &x, f64::from(f32::EPSILON)).0,
            ColumnPattern::Interpolated
        );
    }
}
