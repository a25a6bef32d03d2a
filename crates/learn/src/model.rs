//! A meta-trained LeARN model and its JSON checkpoint.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::adapt::adapt_online;
use crate::columns::ColumnTraining;
use crate::config::{AdaptationConfig, LearnConfig};
use crate::error::{LearnError, Result};
use crate::formulation::Formulation;
use crate::network::Architecture;
use crate::standardiser::Standardiser;

/// The format tag written into every checkpoint.
pub const CHECKPOINT_FORMAT: &str = "learn-checkpoint/1";

/// A data file a model was trained or evaluated on, with its SHA-256.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataFile {
    pub path: PathBuf,
    pub sha256: String,
}

/// Meta-trained parameters with everything needed to use and to reproduce them. Saved as JSON
/// (see [`TrainedOn`] for the two layouts: the paper's flight models and models of CSV tasks).
#[derive(Clone, Debug, PartialEq)]
pub struct MetaTrainedModel {
    /// Always [`CHECKPOINT_FORMAT`].
    pub format: String,
    /// What the inputs X and the outputs ẋ are, and the data the model was meta-trained on.
    pub trained_on: TrainedOn,
    /// The seed of initialisation and task sampling.
    pub seed: u64,
    pub config: LearnConfig,
    pub architecture: Architecture,
    /// Input standardisation (meta-training statistics; the identity when switched off).
    pub standardiser: Standardiser,
    /// θ = [ψ; φ]: each layer of Θ then of ℰ, weights row-major (fan-in × fan-out) then biases.
    pub parameters: Vec<f64>,
    /// The meta-training flights or task files, with their SHA-256.
    pub data_files: Vec<DataFile>,
    /// Mean meta-loss per meta-iteration.
    pub meta_loss_history: Vec<f64>,
}

/// What a model was meta-trained on. In the file, a flight model has the fields `formulation`,
/// `protocol` and `held_out_condition` (as every checkpoint before CSV tasks existed); a model of
/// CSV tasks has `trained_on` instead ([`ColumnTraining`]).
#[derive(Clone, Debug, PartialEq)]
pub enum TrainedOn {
    /// One of the paper's formulations of the Neural-Fly flight logs.
    Flights(FlightTraining),
    /// Named columns of CSV recordings, one task each (`learn meta-train --tasks`).
    Columns(ColumnTraining),
}

/// A flight model's formulation and meta-training flights.
#[derive(Clone, Debug, PartialEq)]
pub struct FlightTraining {
    pub formulation: Formulation,
    /// The name of the protocol that chose the meta-training flights (`paper` or
    /// `leave-condition-out`: the `evaluation` crate's protocols; to this crate only a record).
    pub protocol: String,
    /// The evaluation condition left out of meta-training (`leave-condition-out`), if any.
    pub held_out_condition: Option<String>,
}

/// The fields of a checkpoint file, either layout (read, then checked by [`TryFrom`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CheckpointFields {
    format: String,
    #[serde(default)]
    formulation: Option<Formulation>,
    #[serde(default)]
    protocol: Option<String>,
    #[serde(default)]
    held_out_condition: Option<String>,
    #[serde(default)]
    trained_on: Option<ColumnTraining>,
    seed: u64,
    config: LearnConfig,
    architecture: Architecture,
    standardiser: Standardiser,
    parameters: Vec<f64>,
    data_files: Vec<DataFile>,
    meta_loss_history: Vec<f64>,
}

impl TryFrom<CheckpointFields> for MetaTrainedModel {
    type Error = String;

    fn try_from(fields: CheckpointFields) -> std::result::Result<Self, String> {
        let trained_on = match (fields.trained_on, fields.formulation, fields.protocol) {
            (Some(columns), None, None) if fields.held_out_condition.is_none() => {
                TrainedOn::Columns(columns)
            }
            (Some(_), _, _) => {
                return Err(
                    "a checkpoint has either 'trained_on' (CSV tasks) or 'formulation', \
                     'protocol' and 'held_out_condition' (flights), not both"
                        .to_string(),
                );
            }
            (None, Some(formulation), Some(protocol)) => TrainedOn::Flights(FlightTraining {
                formulation,
                protocol,
                held_out_condition: fields.held_out_condition,
            }),
            (None, None, _) => return Err("missing field `formulation`".to_string()),
            (None, Some(_), None) => return Err("missing field `protocol`".to_string()),
        };
        Ok(Self {
            format: fields.format,
            trained_on,
            seed: fields.seed,
            config: fields.config,
            architecture: fields.architecture,
            standardiser: fields.standardiser,
            parameters: fields.parameters,
            data_files: fields.data_files,
            meta_loss_history: fields.meta_loss_history,
        })
    }
}

impl<'de> Deserialize<'de> for MetaTrainedModel {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        let fields = CheckpointFields::deserialize(deserializer)?;
        Self::try_from(fields).map_err(serde::de::Error::custom)
    }
}

/// A flight model as written before CSV tasks existed (the same fields in the same order).
#[derive(Serialize)]
struct FlightCheckpoint<'a> {
    format: &'a str,
    formulation: Formulation,
    protocol: &'a str,
    held_out_condition: &'a Option<String>,
    #[serde(flatten)]
    rest: CheckpointBody<'a>,
}

/// A model of CSV tasks.
#[derive(Serialize)]
struct ColumnCheckpoint<'a> {
    format: &'a str,
    trained_on: &'a ColumnTraining,
    #[serde(flatten)]
    rest: CheckpointBody<'a>,
}

/// The fields both layouts share, after what the model was trained on.
#[derive(Serialize)]
struct CheckpointBody<'a> {
    seed: u64,
    config: &'a LearnConfig,
    architecture: &'a Architecture,
    standardiser: &'a Standardiser,
    parameters: &'a [f64],
    data_files: &'a [DataFile],
    meta_loss_history: &'a [f64],
}

impl Serialize for MetaTrainedModel {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        let rest = CheckpointBody {
            seed: self.seed,
            config: &self.config,
            architecture: &self.architecture,
            standardiser: &self.standardiser,
            parameters: &self.parameters,
            data_files: &self.data_files,
            meta_loss_history: &self.meta_loss_history,
        };
        match &self.trained_on {
            TrainedOn::Flights(flights) => FlightCheckpoint {
                format: &self.format,
                formulation: flights.formulation,
                protocol: &flights.protocol,
                held_out_condition: &flights.held_out_condition,
                rest,
            }
            .serialize(serializer),
            TrainedOn::Columns(columns) => ColumnCheckpoint {
                format: &self.format,
                trained_on: columns,
                rest,
            }
            .serialize(serializer),
        }
    }
}

impl MetaTrainedModel {
    /// The flight model's formulation and protocol; `None` for a model of CSV tasks.
    pub fn flights(&self) -> Option<&FlightTraining> {
        match &self.trained_on {
            TrainedOn::Flights(flights) => Some(flights),
            TrainedOn::Columns(_) => None,
        }
    }

    /// The flight model's formulation, or an error naming `what` needs one (a model of CSV tasks
    /// has none).
    pub fn formulation_for(&self, what: &str) -> Result<Formulation> {
        self.flights()
            .map(|flights| flights.formulation)
            .ok_or_else(|| LearnError::Mismatch {
                what: what.to_string(),
                message: "needs a model meta-trained on the flight logs (a formulation); this one was meta-trained on CSV tasks".to_string(),
            })
    }

    /// The names of the inputs X, in order: a formulation's (`v_x`, …) or the state then control
    /// columns.
    pub fn input_names(&self) -> Vec<String> {
        match &self.trained_on {
            TrainedOn::Flights(flights) => flights
                .formulation
                .input_names()
                .into_iter()
                .map(str::to_string)
                .collect(),
            TrainedOn::Columns(columns) => columns.input_names(),
        }
    }

    /// The names of the outputs ẋ, in order: a formulation's targets (`vdot_x`, …) or `x'` for
    /// each state column `x`.
    pub fn output_names(&self) -> Vec<String> {
        match &self.trained_on {
            TrainedOn::Flights(flights) => flights.formulation.target_names(),
            TrainedOn::Columns(columns) => columns.output_names(),
        }
    }

    /// The factor each output of the networks is multiplied by (the targets are divided by it
    /// for training and adaptation): `None` for flight models, which learn the targets as they are.
    pub fn output_scale(&self) -> Option<&[f64]> {
        match &self.trained_on {
            TrainedOn::Flights(_) => None,
            TrainedOn::Columns(columns) => Some(&columns.target_scale),
        }
    }

    /// The architecture the configuration gives for this model's inputs and outputs.
    fn expected_architecture(&self) -> Architecture {
        Architecture {
            input_dim: self.input_names().len(),
            state_dim: self.output_names().len(),
            basis_per_input: self.config.basis_per_input,
            hidden: self.config.hidden_layers.clone(),
        }
    }

    /// What the model was trained on, for messages: `formulation 'full'` or `the N state and M
    /// control columns`.
    fn trained_on_text(&self) -> String {
        match &self.trained_on {
            TrainedOn::Flights(flights) => format!("formulation '{}'", flights.formulation.name()),
            TrainedOn::Columns(columns) => format!(
                "the {} state and {} control columns",
                columns.state.len(),
                columns.control.len()
            ),
        }
    }

    /// The name of input `j` (`?` past its inputs), for messages.
    pub(crate) fn input_name(&self, j: usize) -> String {
        self.input_names()
            .get(j)
            .cloned()
            .unwrap_or_else(|| "?".to_string())
    }

    /// Predictions (rows × I, row-major) for raw inputs (rows × (I+U), row-major).
    pub fn predict(&self, raw_inputs: &[f64]) -> Vec<f64> {
        self.predict_with(&self.parameters, raw_inputs)
    }

    /// Predictions (rows × I, row-major) of the networks with `parameters` (e.g. adapted by
    /// [`Self::adapt_on`]) for raw inputs, in the units of the targets.
    pub fn predict_with(&self, parameters: &[f64], raw_inputs: &[f64]) -> Vec<f64> {
        let mut predictions = self
            .architecture
            .predict(parameters, &self.standardiser.apply(raw_inputs));
        if let Some(scale) = self.output_scale() {
            for row in predictions.chunks_exact_mut(scale.len()) {
                row.iter_mut().zip(scale).for_each(|(y, s)| *y *= s);
            }
        }
        predictions
    }

    /// Targets in the units the networks learn (divided by [`Self::output_scale`]).
    pub fn scaled_targets(&self, targets: &[f64]) -> Vec<f64> {
        match self.output_scale() {
            None => targets.to_vec(),
            Some(scale) => targets
                .chunks_exact(scale.len())
                .flat_map(|row| row.iter().zip(scale).map(|(y, s)| y / s))
                .collect(),
        }
    }

    /// θ adapted online (equation online_adapt of the paper, [`adapt_online`]) on raw inputs and
    /// targets in time order, starting from the meta-trained parameters.
    pub fn adapt_on(
        &self,
        raw_inputs: &[f64],
        targets: &[f64],
        adaptation: &AdaptationConfig,
    ) -> Vec<f64> {
        adapt_online(
            &self.architecture,
            &self.parameters,
            &self.standardiser.apply(raw_inputs),
            &self.scaled_targets(targets),
            adaptation,
        )
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
        let text = bounded_read::read_json_text(path).map_err(|cause| LearnError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        let bad = |message: String| LearnError::Checkpoint {
            path: path.to_path_buf(),
            message,
        };
        let model: Self =
            bounded_read::json::from_str(&text).map_err(|error| bad(error.to_string()))?;
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
        if let TrainedOn::Columns(columns) = &model.trained_on {
            columns
                .check()
                .map_err(|message| bad(format!("trained_on: {message}")))?;
        }
        if model.architecture != model.expected_architecture() {
            return Err(bad(format!(
                "architecture does not match the configuration's basis_per_input and hidden_layers for {}",
                model.trained_on_text()
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
        Ok(model)
    }
}
