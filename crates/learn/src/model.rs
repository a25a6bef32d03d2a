//! A meta-trained LeARN model and its JSON checkpoint.

use std::path::{Path, PathBuf};

use data::{Formulation, Segment};
use serde::{Deserialize, Serialize};

use crate::adapt::adapt_online;
use crate::config::{AdaptationConfig, LearnConfig};
use crate::dataset::{Protocol, Standardiser, row_major, segment_batch};
use crate::error::{LearnError, Result};
use crate::network::Architecture;

/// The format tag written into every checkpoint.
pub const CHECKPOINT_FORMAT: &str = "learn-checkpoint/1";

/// A data file a model was trained or evaluated on, with its SHA-256.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataFile {
    pub path: PathBuf,
    pub sha256: String,
}

/// Meta-trained parameters with everything needed to use and to reproduce them. Saved as JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetaTrainedModel {
    /// Always [`CHECKPOINT_FORMAT`].
    pub format: String,
    pub formulation: Formulation,
    pub protocol: Protocol,
    /// The evaluation condition left out of meta-training (`leave-condition-out`), if any.
    pub held_out_condition: Option<String>,
    /// The seed of initialisation and task sampling.
    pub seed: u64,
    pub config: LearnConfig,
    pub architecture: Architecture,
    /// Input standardisation (meta-training statistics; the identity when switched off).
    pub standardiser: Standardiser,
    /// θ = [ψ; φ]: each layer of Θ then of ℰ, weights row-major (fan-in × fan-out) then biases.
    pub parameters: Vec<f64>,
    /// The meta-training flights.
    pub data_files: Vec<DataFile>,
    /// Mean meta-loss per meta-iteration.
    pub meta_loss_history: Vec<f64>,
}

impl MetaTrainedModel {
    /// The name of input `j` of the model's formulation (`?` past its inputs), for messages.
    pub(crate) fn input_name(&self, j: usize) -> &'static str {
        self.formulation
            .input_names()
            .get(j)
            .copied()
            .unwrap_or("?")
    }

    /// Predictions (rows × I, row-major) for raw inputs (rows × (I+U), row-major).
    pub fn predict(&self, raw_inputs: &[f64]) -> Vec<f64> {
        self.architecture
            .predict(&self.parameters, &self.standardiser.apply(raw_inputs))
    }

    /// θ adapted online on `support` (equation online_adapt of the paper, [`adapt_online`]),
    /// starting from the meta-trained parameters, on the standardised inputs in time order.
    pub fn adapt(&self, support: &Segment, adaptation: &AdaptationConfig) -> Vec<f64> {
        let batch = segment_batch(support);
        adapt_online(
            &self.architecture,
            &self.parameters,
            &self.standardiser.apply(&batch.inputs),
            &batch.targets,
            adaptation,
        )
    }

    /// Predictions (samples × I, row-major) of the networks with `parameters` (e.g. adapted by
    /// [`Self::adapt`]) on every sample of `segment`.
    pub fn predict_segment(&self, parameters: &[f64], segment: &Segment) -> Vec<f64> {
        let inputs = self.standardiser.apply(&row_major(&segment.inputs()));
        self.architecture.predict(parameters, &inputs)
    }

    /// Writes the checkpoint as JSON, creating parent directories.
    pub fn save(&self, path: &Path) -> Result<()> {
        let io = |cause| LearnError::Io {
            path: path.to_path_buf(),
            cause,
        };
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).map_err(io)?;
        }
        let text = serde_json::to_string(self).map_err(|error| LearnError::Checkpoint {
            path: path.to_path_buf(),
            message: error.to_string(),
        })?;
        std::fs::write(path, text).map_err(io)
    }

    /// Reads and checks a checkpoint.
    pub fn load(path: &Path) -> Result<Self> {
        let text = inputs::read_json_text(path).map_err(|cause| LearnError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        let bad = |message: String| LearnError::Checkpoint {
            path: path.to_path_buf(),
            message,
        };
        let model: Self = inputs::json::from_str(&text).map_err(|error| bad(error.to_string()))?;
        if model.format != CHECKPOINT_FORMAT {
            return Err(bad(format!(
                "format '{}', expected '{CHECKPOINT_FORMAT}'",
                model.format
            )));
        }
        // The settings the model adapts with are checked as if read from a configuration file.
        model
            .config
            .clone()
            .check(path)
            .map_err(|error| match error {
                LearnError::Config {
                    path,
                    field,
                    message,
                } => LearnError::Config {
                    path,
                    field: format!("config.{field}"),
                    message,
                },
                other => other,
            })?;
        if model.architecture != crate::experiment::architecture(model.formulation, &model.config) {
            return Err(bad(format!(
                "architecture does not match the configuration's basis_per_input and hidden_layers for formulation '{}'",
                model.formulation.name()
            )));
        }
        let expected = model.architecture.parameter_count();
        if model.parameters.len() != expected {
            return Err(bad(format!(
                "{} parameters, the architecture needs {expected}",
                model.parameters.len()
            )));
        }
        let dim = model.architecture.input_dim;
        let standardiser = &model.standardiser;
        let range_fits = standardiser.range.as_ref().is_none_or(|range| {
            range.low.len() == dim
                && range.high.len() == dim
                && range
                    .low
                    .iter()
                    .zip(&range.high)
                    .all(|(low, high)| low <= high)
        });
        if standardiser.mean.len() != dim || standardiser.std.len() != dim || !range_fits {
            return Err(bad(format!(
                "standardiser does not have {dim} features (with low <= high in its range)"
            )));
        }
        if let Some(j) = (0..dim).find(|&j| {
            !(standardiser.mean[j].is_finite()
                && standardiser.std[j].is_finite()
                && standardiser.std[j] > 0.0)
        }) {
            return Err(LearnError::Config {
                path: path.to_path_buf(),
                field: format!("standardiser.std[{j}]"),
                message: format!(
                    "mean {} and std {} of input '{}': the std must be a positive number",
                    standardiser.mean[j],
                    standardiser.std[j],
                    model.input_name(j)
                ),
            });
        }
        if standardiser.clamp && standardiser.range.is_none() {
            return Err(bad("standardiser clamps but has no range".to_string()));
        }
        if model.formulation.input_names().len() != dim
            || model.formulation.state_dim() != model.architecture.state_dim
        {
            return Err(bad(format!(
                "architecture does not fit formulation '{}'",
                model.formulation.name()
            )));
        }
        Ok(model)
    }
}
