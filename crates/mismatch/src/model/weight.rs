//! Where an estimate's weight lies in the recording.
//!
//! A linearised least-squares estimate is a weighted sum of the residual's elements:
//! `x̂ − x = C r` with `C = (JᵀJ)⁻¹Jᵀ` (whitened residual and Jacobian). With residual elements of
//! equal variance, element `s` adds `C_{j,s}²` to parameter `j`'s variance: its weight. A
//! parameter whose weight sits in a few rows (a factor seen only in one manoeuvre) rests on
//! what the model does there, and its standard error assumes the model holds there as it holds
//! elsewhere. The report gives, per parameter, the shortest stretch of rows holding half of it.

use serde::Serialize;

/// The stretch of the recording whose rows hold half of an estimate's weight: from the first
/// row's test function's start to the last one's end, s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WeightSpan {
    pub start_s: f64,
    pub end_s: f64,
}

/// Each row's weight for each parameter: `weights[j][row] = Σ_channels C_{j,(row, channel)}²`,
/// from the Jacobian's columns (`jacobian[i]` flattened row-major, `channels` elements a row)
/// and `inverse = (JᵀJ)⁻¹`. `None` where the inverse is not finite.
pub fn row_weights(
    jacobian: &[Vec<f64>],
    inverse: &[Vec<f64>],
    channels: usize,
) -> Vec<Option<Vec<f64>>> {
    let samples = jacobian.first().map_or(0, Vec::len);
    inverse
        .iter()
        .map(|row_of_inverse| {
            if !row_of_inverse.iter().all(|v| v.is_finite()) {
                return None;
            }
            let weights: Vec<f64> = (0..samples / channels.max(1))
                .map(|row| {
                    (0..channels)
                        .map(|c| {
                            let s = row * channels + c;
                            let along: f64 = row_of_inverse
                                .iter()
                                .zip(jacobian)
                                .map(|(a, column)| a * column[s])
                                .sum();
                            along * along
                        })
                        .sum()
                })
                .collect();
            weights.iter().all(|w| w.is_finite()).then_some(weights)
        })
        .collect()
}

/// The shortest run of rows (by the span of their `time`, increasing) whose `weights` sum to at
/// least half of the total, as `(first, last)` row; `None` without a positive finite total.
pub fn half_weight_rows(time: &[f64], weights: &[f64]) -> Option<(usize, usize)> {
    let total: f64 = weights.iter().sum();
    if !(total.is_finite() && total > 0.0) || time.len() != weights.len() {
        return None;
    }
    let half = 0.5 * total;
    let mut best: Option<(usize, usize)> = None;
    let (mut first, mut sum) = (0, 0.0);
    for (last, w) in weights.iter().enumerate() {
        sum += w;
        while first < last && sum - weights[first] >= half {
            sum -= weights[first];
            first += 1;
        }
        let shorter = best.is_none_or(|(a, b)| time[last] - time[first] < time[b] - time[a]);
        if sum >= half && shorter {
            best = Some((first, last));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_half_weight_is_where_the_weight_is() {
        let time: Vec<f64> = (0..10).map(|k| 0.1 * k as f64).collect();
        let mut weights = vec![1.0; 10];
        weights[6] = 20.0;
        assert_eq!(half_weight_rows(&time, &weights), Some((6, 6)));
        // Spread evenly: five neighbouring rows.
        let even = vec![1.0; 10];
        let (a, b) = half_weight_rows(&time, &even).unwrap();
        assert_eq!(b - a + 1, 5);
        // Two heavy rows far apart hold half only together with what lies between them.
        let mut two = vec![0.25; 10];
        two[1] = 5.0;
        two[8] = 5.0;
        let (a, b) = half_weight_rows(&time, &two).unwrap();
        assert_eq!(b - a, 4);
        assert!((a..=b).contains(&1) || (a..=b).contains(&8));
        assert_eq!(half_weight_rows(&time, &[0.0; 10]), None);
        assert_eq!(half_weight_rows(&time, &[f64::NAN; 10]), None);
    }

    #[test]
    fn uneven_rows_are_measured_in_time() {
        // Rows 0..4 close together, rows 4..8 far apart: the same weight in less time wins.
        let time = [0.0, 0.01, 0.02, 0.03, 1.0, 2.0, 3.0, 4.0];
        let weights = [1.0; 8];
        assert_eq!(half_weight_rows(&time, &weights), Some((0, 3)));
    }

    #[test]
    fn a_row_weight_is_its_share_of_the_variance() {
        // One parameter, J = [1, 2 | 0, 1] (two rows of two channels): (JᵀJ)⁻¹ = 1/6,
        // C = J/6, weights per row (1 + 4)/36 and 1/36; they sum to the variance 1/6.
        let jacobian = vec![vec![1.0, 2.0, 0.0, 1.0]];
        let inverse = vec![vec![1.0 / 6.0]];
        let weights = row_weights(&jacobian, &inverse, 2)[0].clone().unwrap();
        assert!((weights[0] - 5.0 / 36.0).abs() < 1e-15);
        assert!((weights[1] - 1.0 / 36.0).abs() < 1e-15);
        assert!((weights.iter().sum::<f64>() - 1.0 / 6.0).abs() < 1e-15);
        assert_eq!(row_weights(&jacobian, &[vec![f64::NAN]], 2), vec![None]);
    }
}
