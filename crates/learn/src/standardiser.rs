//! Input standardisation ([`Standardiser`]: the meta-training statistics, optionally clamping to
//! the range the meta-training inputs span), how much of a segment lies outside that range
//! ([`RangeCoverage`]), and matrices as the row-major values the networks read.

use faer::Mat;
use serde::{Deserialize, Serialize};

/// The rows of a matrix, concatenated.
pub fn row_major(matrix: &Mat<f64>) -> Vec<f64> {
    let mut values = Vec::with_capacity(matrix.nrows() * matrix.ncols());
    for i in 0..matrix.nrows() {
        for j in 0..matrix.ncols() {
            values.push(matrix[(i, j)]);
        }
    }
    values
}

/// A matrix from row-major values.
pub fn from_row_major(values: &[f64], columns: usize) -> Mat<f64> {
    Mat::from_fn(values.len() / columns, columns, |i, j| {
        values[i * columns + j]
    })
}

/// The z-score of each input feature, (x − mean) / std, optionally of x first clamped to the range
/// the meta-training inputs span.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Standardiser {
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
    /// The range of the raw meta-training inputs (absent in checkpoints written before it was kept).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<InputRange>,
    /// Clamp each raw input to `range` before the z-score, so the networks are never evaluated
    /// outside the box of inputs they were meta-trained on.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub clamp: bool,
}

/// Per-feature bounds of raw inputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputRange {
    pub low: Vec<f64>,
    pub high: Vec<f64>,
}

/// How much of a segment lies outside the range of the meta-training inputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeCoverage {
    /// Samples (rows) of the segment.
    pub samples: usize,
    /// Samples with at least one input outside the range.
    pub samples_outside: usize,
    /// Per input, in the order of X.
    pub inputs: Vec<InputCoverage>,
    /// The model's MSE over the samples inside the range (every input within it), when the
    /// predictions were given and such samples exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mse_inside: Option<f64>,
    /// The model's MSE over the samples outside the range, when the predictions were given and
    /// such samples exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mse_outside: Option<f64>,
}

/// One input's part of a [`RangeCoverage`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InputCoverage {
    pub input: String,
    /// Samples whose value of this input is outside its range.
    pub samples_outside: usize,
    /// The largest distance outside the range, in meta-training standard deviations (0 if none).
    pub largest_excess_in_std: f64,
    /// The part of the model's MSE over the whole segment that comes from the samples outside on
    /// this input: their summed squared error divided by all values of the segment (so the
    /// segment's MSE without them would be lower by this much), when the predictions were given
    /// and such samples exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contribution_to_mse: Option<f64>,
}

impl RangeCoverage {
    /// The mean of several models' coverages of the same segment against the same range (one per
    /// seed: the range comes from the meta-training flights, not from the seed). The counts must
    /// agree and are kept; each MSE field is the mean over the models, or `None` if any lacks it.
    /// `None` for an empty list or counts that disagree.
    pub fn mean(coverages: &[&RangeCoverage]) -> Option<RangeCoverage> {
        let (first, rest) = coverages.split_first()?;
        let same_counts = |other: &RangeCoverage| {
            other.samples == first.samples
                && other.samples_outside == first.samples_outside
                && other.inputs.len() == first.inputs.len()
                && other.inputs.iter().zip(&first.inputs).all(|(a, b)| {
                    a.input == b.input
                        && a.samples_outside == b.samples_outside
                        && a.largest_excess_in_std == b.largest_excess_in_std
                })
        };
        if !rest.iter().all(|other| same_counts(other)) {
            return None;
        }
        let mean = |field: &dyn Fn(&RangeCoverage) -> Option<f64>| {
            let values: Option<Vec<f64>> = coverages.iter().map(|c| field(c)).collect();
            values.map(|values| values.iter().sum::<f64>() / values.len() as f64)
        };
        let mut averaged = (*first).clone();
        averaged.mse_inside = mean(&|c| c.mse_inside);
        averaged.mse_outside = mean(&|c| c.mse_outside);
        for (j, input) in averaged.inputs.iter_mut().enumerate() {
            input.contribution_to_mse = mean(&|c| c.inputs[j].contribution_to_mse);
        }
        Some(averaged)
    }
}

impl InputRange {
    /// The smallest and largest value of each feature over all rows of all batches.
    pub fn spanned<'a>(batches: impl IntoIterator<Item = &'a [f64]>, dim: usize) -> Self {
        let mut range = Self {
            low: vec![f64::INFINITY; dim],
            high: vec![f64::NEG_INFINITY; dim],
        };
        for inputs in batches {
            for row in inputs.chunks_exact(dim) {
                for (k, &x) in row.iter().enumerate() {
                    range.low[k] = range.low[k].min(x);
                    range.high[k] = range.high[k].max(x);
                }
            }
        }
        range
    }
}

impl Standardiser {
    /// The identity (mean 0, std 1) for `dim` features.
    pub fn identity(dim: usize) -> Self {
        Self {
            mean: vec![0.0; dim],
            std: vec![1.0; dim],
            range: None,
            clamp: false,
        }
    }

    /// The same z-score, keeping the range of the meta-training inputs; `clamp`: inputs are
    /// clamped to it before the z-score.
    pub fn with_range(self, range: InputRange, clamp: bool) -> Self {
        Self {
            range: Some(range),
            clamp,
            ..self
        }
    }

    /// How many rows of raw row-major `inputs` (named `names`, in X order) lie outside the kept
    /// range, and how far; `None` without a range.
    pub fn coverage(&self, inputs: &[f64], names: &[&str]) -> Option<RangeCoverage> {
        let range = self.range.as_ref()?;
        let dim = self.mean.len();
        let mut coverage = RangeCoverage {
            samples: inputs.len() / dim,
            samples_outside: 0,
            inputs: names
                .iter()
                .map(|name| InputCoverage {
                    input: name.to_string(),
                    samples_outside: 0,
                    largest_excess_in_std: 0.0,
                    contribution_to_mse: None,
                })
                .collect(),
            mse_inside: None,
            mse_outside: None,
        };
        for row in inputs.chunks_exact(dim) {
            let mut outside = false;
            for (j, &x) in row.iter().enumerate() {
                let excess = (range.low[j] - x).max(x - range.high[j]);
                if excess > 0.0 {
                    outside = true;
                    let input = &mut coverage.inputs[j];
                    input.samples_outside += 1;
                    input.largest_excess_in_std =
                        input.largest_excess_in_std.max(excess / self.std[j]);
                }
            }
            coverage.samples_outside += usize::from(outside);
        }
        Some(coverage)
    }

    /// [`Standardiser::coverage`] with the MSE of `predictions` against `targets` (row-major,
    /// one row per input row) split between the rows inside the kept range and those outside it.
    pub fn coverage_with_errors(
        &self,
        inputs: &[f64],
        names: &[&str],
        predictions: &[f64],
        targets: &[f64],
    ) -> Option<RangeCoverage> {
        let mut coverage = self.coverage(inputs, names)?;
        let range = self.range.as_ref()?;
        let rows = coverage.samples.max(1);
        let outputs = targets.len() / rows;
        if outputs == 0 || self.mean.is_empty() {
            return Some(coverage);
        }
        // (sum of squared errors, values) inside and outside; per input, the squared error of the
        // rows outside on that input.
        let mut sums = [(0.0, 0usize); 2];
        let mut per_input = vec![0.0; self.mean.len()];
        let row_errors = predictions
            .chunks_exact(outputs)
            .zip(targets.chunks_exact(outputs));
        for (row, (predicted, target)) in inputs.chunks_exact(self.mean.len()).zip(row_errors) {
            let squared_error = predicted
                .iter()
                .zip(target)
                .map(|(p, t)| (p - t) * (p - t))
                .sum::<f64>();
            let mut outside = false;
            for (j, &x) in row.iter().enumerate() {
                if x < range.low[j] || x > range.high[j] {
                    outside = true;
                    per_input[j] += squared_error;
                }
            }
            let sum = &mut sums[usize::from(outside)];
            sum.0 += squared_error;
            sum.1 += outputs;
        }
        let mean = |(total, count): (f64, usize)| (count > 0).then(|| total / count as f64);
        coverage.mse_inside = mean(sums[0]);
        coverage.mse_outside = mean(sums[1]);
        let values = (sums[0].1 + sums[1].1) as f64;
        for (input, squared_error) in coverage.inputs.iter_mut().zip(per_input) {
            input.contribution_to_mse = (input.samples_outside > 0).then(|| squared_error / values);
        }
        Some(coverage)
    }

    /// Mean and (population) standard deviation of each feature over all rows of all batches;
    /// a constant feature keeps std 1.
    pub fn fit<'a>(batches: impl IntoIterator<Item = &'a [f64]> + Clone, dim: usize) -> Self {
        let mut count = 0.0;
        let mut mean = vec![0.0; dim];
        for inputs in batches.clone() {
            for row in inputs.chunks_exact(dim) {
                count += 1.0;
                for (m, x) in mean.iter_mut().zip(row) {
                    *m += x;
                }
            }
        }
        mean.iter_mut().for_each(|m| *m /= count);
        let mut variance = vec![0.0; dim];
        for inputs in batches {
            for row in inputs.chunks_exact(dim) {
                for ((v, x), m) in variance.iter_mut().zip(row).zip(&mean) {
                    *v += (x - m) * (x - m);
                }
            }
        }
        let std = variance
            .iter()
            .map(|v| {
                let s = (v / count).sqrt();
                if s > 1e-12 { s } else { 1.0 }
            })
            .collect();
        Self {
            mean,
            std,
            range: None,
            clamp: false,
        }
    }

    /// Standardised copy of row-major inputs (clamped to the range first when `clamp` is set).
    pub fn apply(&self, inputs: &[f64]) -> Vec<f64> {
        let dim = self.mean.len();
        inputs
            .iter()
            .enumerate()
            .map(|(k, &x)| {
                let j = k % dim;
                let x = match &self.range {
                    Some(range) if self.clamp => x.clamp(range.low[j], range.high[j]),
                    _ => x,
                };
                (x - self.mean[j]) / self.std[j]
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamping_standardiser_maps_inputs_outside_the_range_to_its_bounds() {
        let rows = [1.0, -2.0, 3.0, 0.0, 2.0, 4.0];
        let range = InputRange::spanned([&rows[..]], 2);
        assert_eq!(range.low, vec![1.0, -2.0]);
        assert_eq!(range.high, vec![3.0, 4.0]);
        let plain = Standardiser::fit([&rows[..]], 2);
        let kept = plain.clone().with_range(range.clone(), false);
        let clamped = plain.clone().with_range(range, true);
        let inside = [2.5, 1.0];
        assert_eq!(clamped.apply(&inside), plain.apply(&inside));
        let outside = [10.0, -7.0];
        assert_eq!(kept.apply(&outside), plain.apply(&outside));
        assert_eq!(clamped.apply(&outside), plain.apply(&[3.0, -2.0]));
        assert_ne!(plain.apply(&outside), plain.apply(&[3.0, -2.0]));
    }

    #[test]
    fn coverage_counts_samples_outside_the_range_and_their_largest_excess() {
        let training = [0.0, 0.0, 2.0, 4.0];
        let standardiser = Standardiser::fit([&training[..]], 2)
            .with_range(InputRange::spanned([&training[..]], 2), false);
        assert_eq!(standardiser.std, vec![1.0, 2.0]);
        // Rows: inside; x above by 1.5 (1.5 std); y below by 2 (1 std) and x above by 0.5.
        let segment = [1.0, 2.0, 3.5, 1.0, 2.5, -2.0];
        let coverage = standardiser.coverage(&segment, &["x", "y"]).unwrap();
        assert_eq!(coverage.samples, 3);
        assert_eq!(coverage.samples_outside, 2);
        assert_eq!(coverage.inputs[0].samples_outside, 2);
        assert_eq!(coverage.inputs[0].largest_excess_in_std, 1.5);
        assert_eq!(coverage.inputs[1].samples_outside, 1);
        assert_eq!(coverage.inputs[1].largest_excess_in_std, 1.0);
        assert_eq!(
            Standardiser::fit([&training[..]], 2).coverage(&segment, &["x", "y"]),
            None
        );
    }

    #[test]
    fn coverage_splits_the_squared_error_between_rows_inside_and_outside_the_range() {
        let training = [0.0, 0.0, 2.0, 4.0];
        let standardiser = Standardiser::fit([&training[..]], 2)
            .with_range(InputRange::spanned([&training[..]], 2), false);
        // The same three rows as above (inside, outside, outside), two outputs each.
        let segment = [1.0, 2.0, 3.5, 1.0, 2.5, -2.0];
        let predictions = [1.0, 1.0, 0.0, 0.0, 5.0, 5.0];
        let targets = [0.0, 3.0, 2.0, 0.0, 5.0, 3.0];
        let coverage = standardiser
            .coverage_with_errors(&segment, &["x", "y"], &predictions, &targets)
            .unwrap();
        assert_eq!(coverage.samples_outside, 2);
        assert_eq!(coverage.mse_inside, Some((1.0 + 4.0) / 2.0));
        assert_eq!(coverage.mse_outside, Some((4.0 + 0.0 + 0.0 + 4.0) / 4.0));
        // x is outside on rows 2 and 3 (squared errors 4 and 4), y on row 3 only; 6 values in all.
        // The per-input parts overlap (row 3 counts for both) and lie within the MSE.
        assert_eq!(coverage.inputs[0].contribution_to_mse, Some(8.0 / 6.0));
        assert_eq!(coverage.inputs[1].contribution_to_mse, Some(4.0 / 6.0));
        // No row outside: no MSE outside.
        let inside_only = standardiser
            .coverage_with_errors(&segment[..2], &["x", "y"], &predictions[..2], &targets[..2])
            .unwrap();
        assert_eq!(
            (inside_only.mse_inside, inside_only.mse_outside),
            (Some(2.5), None)
        );
        assert!(
            inside_only
                .inputs
                .iter()
                .all(|input| input.contribution_to_mse.is_none())
        );
    }

    #[test]
    fn the_mean_coverage_keeps_the_counts_and_averages_the_errors() {
        let training = [0.0, 0.0, 2.0, 4.0];
        let standardiser = Standardiser::fit([&training[..]], 2)
            .with_range(InputRange::spanned([&training[..]], 2), false);
        let segment = [1.0, 2.0, 3.5, 1.0, 2.5, -2.0];
        let targets = [0.0; 6];
        let one = standardiser
            .coverage_with_errors(&segment, &["x", "y"], &[1.0; 6], &targets)
            .unwrap();
        let two = standardiser
            .coverage_with_errors(&segment, &["x", "y"], &[3.0; 6], &targets)
            .unwrap();
        let mean = RangeCoverage::mean(&[&one, &two]).unwrap();
        assert_eq!(mean.samples_outside, 2);
        assert_eq!(mean.mse_inside, Some(5.0));
        assert_eq!(mean.mse_outside, Some(5.0));
        // x is outside on two of three rows: (2·2·1 + 2·2·9) / 2 / 6.
        assert_eq!(mean.inputs[0].contribution_to_mse, Some(20.0 / 6.0));
        assert_eq!(RangeCoverage::mean(&[&one]), Some(one.clone()));
        assert_eq!(RangeCoverage::mean(&[]), None);
        // Another segment: the counts disagree.
        let other = standardiser.coverage(&segment[..2], &["x", "y"]).unwrap();
        assert_eq!(RangeCoverage::mean(&[&one, &other]), None);
        // A coverage without errors leaves the mean without them.
        let without = standardiser.coverage(&segment, &["x", "y"]).unwrap();
        assert_eq!(
            RangeCoverage::mean(&[&one, &without]).unwrap().mse_inside,
            None
        );
    }

    #[test]
    fn a_checkpoint_standardiser_without_a_range_reads_and_writes_as_before() {
        let text = r#"{"mean":[0.5],"std":[2.0]}"#;
        let standardiser: Standardiser = serde_json::from_str(text).unwrap();
        assert_eq!(standardiser.range, None);
        assert!(!standardiser.clamp);
        assert_eq!(serde_json::to_string(&standardiser).unwrap(), text);
    }

    #[test]
    fn a_misspelt_standardiser_field_is_an_error_not_a_default() {
        let text = r#"{"mean":[0.5],"std":[2.0],"clmap":true}"#;
        let error = serde_json::from_str::<Standardiser>(text).unwrap_err();
        assert!(error.to_string().contains("clmap"), "{error}");
        let text = r#"{"mean":[0.5],"std":[2.0],"range":{"low":[0.0],"high":[1.0],"hi":[2.0]}}"#;
        assert!(serde_json::from_str::<Standardiser>(text).is_err());
    }
}
