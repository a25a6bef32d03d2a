//! From flight logs to regression data: protocols, meta-training flights, standardisation.

use std::path::{Path, PathBuf};

use data::{Derivative, ExperimentConditions, FlightLog, Formulation, Mat, Segment, SplitSpec};
use serde::{Deserialize, Serialize};

use crate::error::{LearnError, Result};
use crate::maml::Batch;

/// Which flights meta-train the model for an evaluation condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// The paper's meta-training flights `training/custom_random3_baseline_*.csv` (all six).
    Paper,
    /// For evaluation condition c: every shared figure-8 flight whose condition is not c, all
    /// controllers. The evaluated flight and its wind speed are never seen during meta-training.
    LeaveConditionOut,
}

impl Protocol {
    /// The name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::LeaveConditionOut => "leave-condition-out",
        }
    }

    /// Parses `paper`, `leave-condition-out` or `auto` (None: decide from the data present).
    pub fn parse(text: &str) -> Result<Option<Self>> {
        match text {
            "paper" => Ok(Some(Self::Paper)),
            "leave-condition-out" => Ok(Some(Self::LeaveConditionOut)),
            "auto" => Ok(None),
            other => Err(LearnError::UnknownProtocol {
                name: other.to_string(),
            }),
        }
    }

    /// `requested`, or when None: `paper` if the paper's training flights are present, otherwise
    /// `leave-condition-out`.
    pub fn resolve(
        requested: Option<Self>,
        conditions: &ExperimentConditions,
        data_dir: &Path,
    ) -> Self {
        requested.unwrap_or(if conditions.paper_training_present(data_dir) {
            Self::Paper
        } else {
            Self::LeaveConditionOut
        })
    }

    /// The meta-training flight files for `evaluation_condition` (a name or label).
    pub fn training_files(
        &self,
        conditions: &ExperimentConditions,
        data_dir: &Path,
        evaluation_condition: &str,
    ) -> Result<Vec<PathBuf>> {
        let held_out = conditions.condition(evaluation_condition)?;
        let files = conditions.flight_files(data_dir);
        let chosen: Vec<PathBuf> = match self {
            Self::Paper => {
                let paper: Vec<_> = files
                    .iter()
                    .filter(|f| f.controller == "paper-training")
                    .collect();
                if let Some(missing) = paper.iter().find(|f| !f.present) {
                    return Err(LearnError::NoTrainingFlights {
                        protocol: self.name().to_string(),
                        condition: held_out.name.clone(),
                        detail: format!("{} is missing", missing.path.display()),
                    });
                }
                paper.iter().map(|f| f.path.clone()).collect()
            }
            Self::LeaveConditionOut => files
                .iter()
                .filter(|f| {
                    f.controller != "paper-training" && f.condition != held_out.name && f.present
                })
                .map(|f| f.path.clone())
                .collect(),
        };
        if chosen.is_empty() {
            return Err(LearnError::NoTrainingFlights {
                protocol: self.name().to_string(),
                condition: held_out.name.clone(),
                detail: format!("no flight file present under {}", data_dir.display()),
            });
        }
        Ok(chosen)
    }
}

/// The support and query segments of a flight (SplitSpec::Halves, forward-difference targets on
/// each segment separately): the same data as the SINDy columns.
pub fn flight_segments(log: &FlightLog, formulation: Formulation) -> Result<(Segment, Segment)> {
    let split = SplitSpec::Halves.split(log.len())?;
    let support = formulation.segment(log, split.support, Derivative::Forward)?;
    let query = formulation.segment(log, split.query, Derivative::Forward)?;
    Ok((support, query))
}

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

/// A segment as regression data with raw (not standardised) inputs.
pub fn segment_batch(segment: &Segment) -> Batch {
    Batch {
        inputs: row_major(&segment.inputs()),
        targets: row_major(&segment.targets),
    }
}

/// The z-score of each input feature, (x − mean) / std, optionally of x first clamped to a range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Standardiser {
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
    /// When present, each raw input is clamped to `[low, high]` before the z-score, so the
    /// networks are never evaluated outside the box of inputs they were meta-trained on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<InputRange>,
}

/// Per-feature bounds of raw inputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InputRange {
    pub low: Vec<f64>,
    pub high: Vec<f64>,
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
        }
    }

    /// The same z-score of inputs first clamped to `range`.
    pub fn clamped_to(self, range: InputRange) -> Self {
        Self {
            range: Some(range),
            ..self
        }
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
        }
    }

    /// Standardised copy of row-major inputs (clamped first when a range is set).
    pub fn apply(&self, inputs: &[f64]) -> Vec<f64> {
        let dim = self.mean.len();
        inputs
            .iter()
            .enumerate()
            .map(|(k, &x)| {
                let j = k % dim;
                let x = match &self.range {
                    Some(range) => x.clamp(range.low[j], range.high[j]),
                    None => x,
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
        let clamped = plain.clone().clamped_to(range);
        let inside = [2.5, 1.0];
        assert_eq!(clamped.apply(&inside), plain.apply(&inside));
        let outside = [10.0, -7.0];
        assert_eq!(clamped.apply(&outside), plain.apply(&[3.0, -2.0]));
        assert_ne!(plain.apply(&outside), plain.apply(&[3.0, -2.0]));
    }

    #[test]
    fn a_checkpoint_standardiser_without_a_range_reads_and_writes_as_before() {
        let text = r#"{"mean":[0.5],"std":[2.0]}"#;
        let standardiser: Standardiser = serde_json::from_str(text).unwrap();
        assert_eq!(standardiser.range, None);
        assert_eq!(serde_json::to_string(&standardiser).unwrap(), text);
    }
}
