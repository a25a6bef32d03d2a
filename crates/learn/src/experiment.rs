//! The experiment the tables report: meta-train per (formulation, evaluation condition), adapt
//! online on the evaluation flight's support segment, predict its query segment.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use data::{Condition, ExperimentConditions, FlightLog, Formulation, Mat, Role, file_sha256};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::adapt::adapt_online;
use crate::config::{AdaptationConfig, CheckedConfig, LearnConfig, TaskGrouping};
use crate::dataset::{
    InputRange, Protocol, RangeCoverage, Standardiser, flight_segments, from_row_major,
    segment_batch,
};
use crate::error::{LearnError, Result};
use crate::maml::Batch;
use crate::model::{CHECKPOINT_FORMAT, DataFile, FlightTraining, MetaTrainedModel, TrainedOn};
use crate::network::{Architecture, mean_squared_error};
use crate::train::{MetaTrainingOutcome, TaskData, check_sampling, meta_train};

/// A flight log with its file's SHA-256.
struct LoadedFlight {
    log: FlightLog,
    sha256: String,
}

/// Configuration, conditions, protocol and every flight needed, loaded once.
pub struct Experiment {
    config: CheckedConfig,
    conditions: ExperimentConditions,
    data_dir: PathBuf,
    protocol: Protocol,
    flights: BTreeMap<PathBuf, LoadedFlight>,
}

/// One segment of the evaluation flight: time, targets and the adapted model's predictions.
#[derive(Clone, Debug)]
pub struct SegmentPrediction {
    pub time: Vec<f64>,
    /// ẋ (forward difference on this segment), samples × I.
    pub targets: Mat<f64>,
    /// The adapted model's predictions, samples × I.
    pub predictions: Mat<f64>,
}

/// The numbers of one table cell, as written to JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellSummary {
    pub formulation: Formulation,
    /// The condition's file name, e.g. `70p20sint`.
    pub condition: String,
    /// The condition as printed in tables, e.g. `70psin20`.
    pub label: String,
    pub protocol: Protocol,
    pub seed: u64,
    /// The adapted model on the support segment.
    pub adapt_mse: f64,
    /// The adapted model, frozen, on the query segment.
    pub gen_mse: f64,
    /// The meta-trained model before adaptation, on the support segment.
    pub unadapted_adapt_mse: f64,
    /// The meta-trained model before adaptation, on the query segment.
    pub unadapted_gen_mse: f64,
    /// The evaluated flight.
    pub evaluation_file: DataFile,
    /// How much of the support segment lies outside the range of the meta-training inputs.
    pub support_coverage: Option<RangeCoverage>,
    /// How much of the query segment lies outside that range (the networks extrapolate there).
    pub query_coverage: Option<RangeCoverage>,
}

/// A model meta-trained for a nested-validation pair, with the pair's conditions.
struct NestedModel<'a> {
    first: &'a data::Condition,
    second: &'a data::Condition,
    architecture: Architecture,
    standardiser: Standardiser,
    outcome: MetaTrainingOutcome,
}

/// One evaluation flight of a nested-validation pair ([`Experiment::nested_validation_detail`]).
#[derive(Clone, Debug)]
pub struct ValidationDetail {
    /// Generalisation MSE after adaptation on the whole support segment.
    pub query_mse: f64,
    /// MSE on the support segment's tail after adaptation on the rest of it.
    pub support_tail_mse: f64,
    /// The adapted model's query predictions, row-major, samples × I.
    pub query_predictions: Vec<f64>,
    /// The query targets, row-major, samples × I.
    pub query_targets: Vec<f64>,
}

/// Everything one cell produces.
#[derive(Clone, Debug)]
pub struct CellResult {
    pub summary: CellSummary,
    pub support: SegmentPrediction,
    pub query: SegmentPrediction,
    /// The meta-trained model (the checkpoint).
    pub model: MetaTrainedModel,
    /// θ after online adaptation on the support segment.
    pub adapted_parameters: Vec<f64>,
}

impl Experiment {
    /// Resolves the protocol (`None`: `paper` if its flights are present, else
    /// `leave-condition-out`) and reads every flight it needs, in parallel.
    pub fn load(
        config: CheckedConfig,
        conditions: ExperimentConditions,
        data_dir: &Path,
        protocol: Option<Protocol>,
    ) -> Result<Self> {
        let protocol = Protocol::resolve(protocol, &conditions, data_dir);
        let mut paths: Vec<PathBuf> = Vec::new();
        for condition in conditions.evaluation() {
            paths.push(conditions.flight_path(
                data_dir,
                condition,
                &conditions.evaluation_controller,
            ));
            paths.extend(protocol.training_files(&conditions, data_dir, &condition.name)?);
        }
        paths.sort();
        paths.dedup();
        let loaded: Vec<(PathBuf, LoadedFlight)> = paths
            .par_iter()
            .map(|path| {
                let log = FlightLog::read(path)?;
                let sha256 = file_sha256(path)?;
                Ok((path.clone(), LoadedFlight { log, sha256 }))
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            config,
            conditions,
            data_dir: data_dir.to_path_buf(),
            protocol,
            flights: loaded.into_iter().collect(),
        })
    }

    /// The protocol every result of this experiment is produced under.
    pub fn protocol(&self) -> Protocol {
        self.protocol
    }

    /// The configuration.
    pub fn config(&self) -> &CheckedConfig {
        &self.config
    }

    /// The names of the evaluation conditions, in table order.
    pub fn evaluation_conditions(&self) -> Vec<String> {
        self.conditions
            .evaluation()
            .map(|c| c.name.clone())
            .collect()
    }

    /// Every flight this experiment read (relative to the data directory), with its SHA-256, in
    /// path order.
    pub fn data_files(&self) -> Vec<DataFile> {
        self.flights
            .iter()
            .map(|(path, flight)| DataFile {
                path: path
                    .strip_prefix(&self.data_dir)
                    .unwrap_or(path)
                    .to_path_buf(),
                sha256: flight.sha256.clone(),
            })
            .collect()
    }

    fn flight(&self, path: &Path) -> Result<&LoadedFlight> {
        self.flights.get(path).ok_or_else(|| LearnError::Mismatch {
            what: path.display().to_string(),
            message: "flight was not loaded by this experiment".to_string(),
        })
    }

    fn data_file(&self, path: &Path) -> Result<DataFile> {
        Ok(DataFile {
            path: path
                .strip_prefix(&self.data_dir)
                .unwrap_or(path)
                .to_path_buf(),
            sha256: self.flight(path)?.sha256.clone(),
        })
    }

    /// Meta-trains a model for `formulation`, leaving out `evaluation_condition` under
    /// `leave-condition-out` (under `paper` the condition only names the fold). A condition that
    /// is not an evaluation condition (role `meta-training`) is refused: it names no fold.
    pub fn meta_train(
        &self,
        formulation: Formulation,
        evaluation_condition: &str,
        seed: u64,
    ) -> Result<MetaTrainedModel> {
        let held_out = evaluation_condition_of(&self.conditions, evaluation_condition)?
            .name
            .clone();
        let config = self.config.get();
        let files =
            self.protocol
                .training_files(&self.conditions, &self.data_dir, evaluation_condition)?;
        let cell = format!("{} {evaluation_condition}", formulation.name());
        let (architecture, standardiser, outcome) =
            self.meta_train_on(formulation, &files, config, seed, &cell)?;
        let data_files = files
            .iter()
            .map(|path| self.data_file(path))
            .collect::<Result<_>>()?;
        Ok(MetaTrainedModel {
            format: CHECKPOINT_FORMAT.to_string(),
            trained_on: TrainedOn::Flights(FlightTraining {
                formulation,
                protocol: self.protocol,
                held_out_condition: (self.protocol == Protocol::LeaveConditionOut)
                    .then_some(held_out),
            }),
            seed,
            config: config.clone(),
            architecture,
            standardiser,
            parameters: outcome.parameters,
            data_files,
            meta_loss_history: outcome.meta_loss_history,
        })
    }

    /// Meta-trains on `files` with `config` (inputs standardised with these files' statistics);
    /// `cell` names the run in errors.
    fn meta_train_on(
        &self,
        formulation: Formulation,
        files: &[PathBuf],
        config: &LearnConfig,
        seed: u64,
        cell: &str,
    ) -> Result<(Architecture, Standardiser, MetaTrainingOutcome)> {
        let mut raw_tasks = Vec::with_capacity(files.len());
        for path in files {
            let (support, query) = flight_segments(&self.flight(path)?.log, formulation)?;
            raw_tasks.push((path, segment_batch(&support), segment_batch(&query)));
        }
        let input_dim = formulation.input_names().len();
        let standardiser = if config.standardise_inputs {
            Standardiser::fit(
                raw_tasks
                    .iter()
                    .flat_map(|(_, s, q)| [s.inputs.as_slice(), q.inputs.as_slice()]),
                input_dim,
            )
        } else {
            Standardiser::identity(input_dim)
        };
        let range = InputRange::spanned(
            raw_tasks
                .iter()
                .flat_map(|(_, s, q)| [s.inputs.as_slice(), q.inputs.as_slice()]),
            input_dim,
        );
        let standardiser = standardiser.with_range(range, config.clamp_inputs);
        let tasks: Vec<TaskData> = self
            .grouped(raw_tasks, config.meta_training.tasks)
            .into_iter()
            .map(|(name, support, query)| TaskData {
                name,
                support: standardised(&standardiser, support),
                query: standardised(&standardiser, query),
            })
            .collect();
        let architecture = architecture(formulation, config);
        let origin = self.config.origin();
        check_sampling(&config.meta_training, &tasks, architecture.input_dim).map_err(
            |(field, message)| LearnError::Config {
                path: origin.to_path_buf(),
                field: field.to_string(),
                message,
            },
        )?;
        let outcome = meta_train(&architecture, &tasks, &config.meta_training, seed).map_err(
            |error| match error {
                LearnError::Diverged { iteration, loss } => LearnError::NotFinite {
                    cell: cell.to_string(),
                    message: format!(
                        "meta-training diverged at iteration {iteration} (loss {loss}); lower meta_training.outer_step or meta_training.inner_step in {}",
                        origin.display()
                    ),
                },
                other => other,
            },
        )?;
        Ok((architecture, standardiser, outcome))
    }

    /// The meta-training tasks of `flights` (path, support, query) under `grouping`: one per flight,
    /// named by its path, or one per wind condition, named by the condition, pooling its flights'
    /// segments in file order (conditions in the order of their first flight).
    fn grouped(
        &self,
        flights: Vec<(&PathBuf, Batch, Batch)>,
        grouping: TaskGrouping,
    ) -> Vec<(String, Batch, Batch)> {
        match grouping {
            TaskGrouping::Flight => flights
                .into_iter()
                .map(|(path, support, query)| (path.display().to_string(), support, query))
                .collect(),
            TaskGrouping::Condition => {
                let known = self.conditions.flight_files(&self.data_dir);
                let condition_of = |path: &PathBuf| {
                    known
                        .iter()
                        .find(|file| &file.path == path)
                        .map_or_else(|| path.display().to_string(), |file| file.condition.clone())
                };
                let mut groups: Vec<(String, Batch, Batch)> = Vec::new();
                for (path, support, query) in flights {
                    let condition = condition_of(path);
                    match groups.iter_mut().find(|(name, _, _)| name == &condition) {
                        Some((_, pooled_support, pooled_query)) => {
                            pooled_support.append(support);
                            pooled_query.append(query);
                        }
                        None => groups.push((condition, support, query)),
                    }
                }
                groups
            }
        }
    }

    /// Nested validation inside the meta-training sets (leave-condition-out only). For two
    /// evaluation conditions a and b, the flights of neither form the meta-training set of fold a
    /// without condition b, which is also that of fold b without condition a. Meta-trains on it with
    /// `config`, then for each of a and b adapts online on the support segment of its evaluation
    /// flight with each of `adaptations` and returns the generalisation MSE on its query segment:
    /// `[for a, for b]`, one value per adaptation setting. The score on b lies inside fold a's
    /// meta-training data, so settings chosen with these scores never see fold a's evaluation flight
    /// (and symmetrically).
    pub fn nested_validation(
        &self,
        formulation: Formulation,
        pair: [&str; 2],
        config: &LearnConfig,
        adaptations: &[AdaptationConfig],
        seed: u64,
    ) -> Result<[Vec<f64>; 2]> {
        // The candidate settings are checked as a configuration read from the experiment's file.
        let origin = self.config.origin();
        let config = config.clone().check(origin)?;
        let config = config.get();
        for adaptation in adaptations {
            LearnConfig {
                adaptation: adaptation.clone(),
                ..config.clone()
            }
            .check(origin)?;
        }
        let NestedModel {
            first,
            second,
            architecture,
            standardiser,
            outcome,
        } = self.nested_meta_train(formulation, pair, config, seed)?;
        let score = |condition: &data::Condition| -> Result<Vec<f64>> {
            let path = self.conditions.flight_path(
                &self.data_dir,
                condition,
                &self.conditions.evaluation_controller,
            );
            let (support, query) = flight_segments(&self.flight(&path)?.log, formulation)?;
            for adaptation in adaptations {
                check_window(adaptation, &support, &path, origin)?;
            }
            let support_batch = standardised(&standardiser, segment_batch(&support));
            let query_batch = standardised(&standardiser, segment_batch(&query));
            Ok(adaptations
                .iter()
                .map(|adaptation| {
                    let adapted = adapt_online(
                        &architecture,
                        &outcome.parameters,
                        &support_batch.inputs,
                        &support_batch.targets,
                        adaptation,
                    );
                    architecture.loss(&adapted, &query_batch.inputs, &query_batch.targets)
                })
                .collect())
        };
        Ok([score(first)?, score(second)?])
    }

    /// Meta-trains with `config` on the flights of neither condition of a nested-validation pair
    /// (the shared meta-training set of [`Experiment::nested_validation`]).
    fn nested_meta_train(
        &self,
        formulation: Formulation,
        pair: [&str; 2],
        config: &LearnConfig,
        seed: u64,
    ) -> Result<NestedModel<'_>> {
        let first = self.conditions.condition(pair[0])?;
        let second = self.conditions.condition(pair[1])?;
        if self.protocol != Protocol::LeaveConditionOut || first.name == second.name {
            return Err(LearnError::Mismatch {
                what: format!("nested validation {}/{}", pair[0], pair[1]),
                message: "needs leave-condition-out and two different conditions".to_string(),
            });
        }
        let second_files: Vec<PathBuf> = self
            .conditions
            .flight_files(&self.data_dir)
            .into_iter()
            .filter(|f| f.condition == second.name)
            .map(|f| f.path)
            .collect();
        let files: Vec<PathBuf> = self
            .protocol
            .training_files(&self.conditions, &self.data_dir, &first.name)?
            .into_iter()
            .filter(|path| !second_files.contains(path))
            .collect();
        let cell = format!(
            "{} nested validation {}/{}",
            formulation.name(),
            first.name,
            second.name
        );
        let (architecture, standardiser, outcome) =
            self.meta_train_on(formulation, &files, config, seed, &cell)?;
        Ok(NestedModel {
            first,
            second,
            architecture,
            standardiser,
            outcome,
        })
    }

    /// [`Experiment::nested_validation`] with the configured settings, keeping what a comparison
    /// across seeds needs: for each condition of the pair, the generalisation MSE, the query
    /// predictions and targets (standardised inputs, raw targets), and the **support-tail MSE**:
    /// the model adapted on the first `1 − tail_fraction` of the support segment, scored on the
    /// rest (a held-out score that uses the support segment only, as a method could at run time).
    pub fn nested_validation_detail(
        &self,
        formulation: Formulation,
        pair: [&str; 2],
        seed: u64,
        tail_fraction: f64,
    ) -> Result<[ValidationDetail; 2]> {
        if !(tail_fraction > 0.0 && tail_fraction < 1.0) {
            return Err(LearnError::Mismatch {
                what: format!("support tail fraction {tail_fraction}"),
                message: "must lie strictly between 0 and 1".to_string(),
            });
        }
        let config = self.config.get();
        let NestedModel {
            first,
            second,
            architecture,
            standardiser,
            outcome,
        } = self.nested_meta_train(formulation, pair, config, seed)?;
        let adaptation = &config.adaptation;
        let (input_dim, output_dim) = (architecture.input_dim, architecture.state_dim);
        let detail = |condition: &data::Condition| -> Result<ValidationDetail> {
            let path = self.conditions.flight_path(
                &self.data_dir,
                condition,
                &self.conditions.evaluation_controller,
            );
            let (support, query) = flight_segments(&self.flight(&path)?.log, formulation)?;
            let support = standardised(&standardiser, segment_batch(&support));
            let query = standardised(&standardiser, segment_batch(&query));
            let adapt = |rows: usize| {
                adapt_online(
                    &architecture,
                    &outcome.parameters,
                    &support.inputs[..rows * input_dim],
                    &support.targets[..rows * output_dim],
                    adaptation,
                )
            };
            let rows = support.inputs.len() / input_dim;
            let head_rows = ((rows as f64) * (1.0 - tail_fraction)).round() as usize;
            let head_rows = head_rows.clamp(1, rows.saturating_sub(1));
            let head = adapt(head_rows);
            let support_tail_mse = architecture.loss(
                &head,
                &support.inputs[head_rows * input_dim..],
                &support.targets[head_rows * output_dim..],
            );
            let adapted = adapt(rows);
            Ok(ValidationDetail {
                query_mse: architecture.loss(&adapted, &query.inputs, &query.targets),
                support_tail_mse,
                query_predictions: architecture.predict(&adapted, &query.inputs),
                query_targets: query.targets,
            })
        };
        Ok([detail(first)?, detail(second)?])
    }

    /// Adapts `model` online on the support segment of the evaluation flight of
    /// `evaluation_condition` and predicts both segments. Refuses a condition that is not an
    /// evaluation condition, and a `leave-condition-out` model that was not trained for this
    /// condition's fold.
    pub fn evaluate(
        &self,
        model: &MetaTrainedModel,
        evaluation_condition: &str,
    ) -> Result<CellResult> {
        let condition = evaluation_condition_of(&self.conditions, evaluation_condition)?;
        let flights = model.flights().ok_or_else(|| LearnError::Mismatch {
            what: format!("evaluation on '{}'", condition.name),
            message: "the model was meta-trained on CSV tasks, not on the flights".to_string(),
        })?;
        let formulation = flights.formulation;
        if let Some(held_out) = &flights.held_out_condition
            && held_out != &condition.name
        {
            return Err(LearnError::Mismatch {
                what: format!("evaluation on '{}'", condition.name),
                message: format!(
                    "the model was meta-trained with '{held_out}' left out, not this condition"
                ),
            });
        }
        let path = self.conditions.flight_path(
            &self.data_dir,
            condition,
            &self.conditions.evaluation_controller,
        );
        let log = &self.flight(&path)?.log;
        let (support, query) = flight_segments(log, formulation)?;
        let (raw_support, raw_query) = (segment_batch(&support), segment_batch(&query));
        let input_names = formulation.input_names();
        let support_batch = standardised(&model.standardiser, raw_support.clone());
        let query_batch = standardised(&model.standardiser, raw_query.clone());
        let architecture = &model.architecture;
        let origin = self.config.origin();
        let adaptation = &self.config.get().adaptation;
        check_window(adaptation, &support, &path, origin)?;
        let cell = format!("{} {}", formulation.name(), condition.name);
        // The meta-trained model before adaptation: when it already gives non-finite numbers the
        // adaptation settings are not the cause.
        let unadapted_adapt_mse = architecture.loss(
            &model.parameters,
            &support_batch.inputs,
            &support_batch.targets,
        );
        let unadapted_gen_mse =
            architecture.loss(&model.parameters, &query_batch.inputs, &query_batch.targets);
        for (name, value) in [
            ("unadapted adaptation MSE", unadapted_adapt_mse),
            ("unadapted generalisation MSE", unadapted_gen_mse),
        ] {
            if !value.is_finite() {
                return Err(LearnError::NotFinite {
                    cell,
                    message: format!(
                        "the meta-trained model gives a non-finite {name} ({value}) before any adaptation: the meta-trained parameters or the input standardisation, not the adaptation settings, are the cause (see meta_training in {})",
                        origin.display()
                    ),
                });
            }
        }
        let adapted = model.adapt(&support, adaptation);
        let advice = format!(
            "lower adaptation.step or adaptation.lipschitz_weight in {}",
            origin.display()
        );
        check_finite_parameters(&adapted, &cell, &advice)?;
        let support_predictions = model.predict_segment(&adapted, &support);
        let query_predictions = model.predict_segment(&adapted, &query);
        let support_coverage = model.standardiser.coverage_with_errors(
            &raw_support.inputs,
            &input_names,
            &support_predictions,
            &support_batch.targets,
        );
        let query_coverage = model.standardiser.coverage_with_errors(
            &raw_query.inputs,
            &input_names,
            &query_predictions,
            &query_batch.targets,
        );
        let state_dim = architecture.state_dim;
        let summary = CellSummary {
            formulation,
            condition: condition.name.clone(),
            label: condition.label().to_string(),
            protocol: flights.protocol,
            seed: model.seed,
            adapt_mse: mean_squared_error(&support_predictions, &support_batch.targets),
            gen_mse: mean_squared_error(&query_predictions, &query_batch.targets),
            unadapted_adapt_mse,
            unadapted_gen_mse,
            evaluation_file: self.data_file(&path)?,
            support_coverage,
            query_coverage,
        };
        for (name, value) in [
            ("adaptation MSE", summary.adapt_mse),
            ("generalisation MSE", summary.gen_mse),
        ] {
            if !value.is_finite() {
                return Err(LearnError::NotFinite {
                    cell,
                    message: format!("the {name} is not finite ({value}); {advice}"),
                });
            }
        }
        Ok(CellResult {
            summary,
            support: SegmentPrediction {
                time: support.time.clone(),
                targets: support.targets.clone(),
                predictions: from_row_major(&support_predictions, state_dim),
            },
            query: SegmentPrediction {
                time: query.time.clone(),
                targets: query.targets.clone(),
                predictions: from_row_major(&query_predictions, state_dim),
            },
            model: model.clone(),
            adapted_parameters: adapted,
        })
    }

    /// Meta-trains and evaluates one cell.
    pub fn run_cell(
        &self,
        formulation: Formulation,
        evaluation_condition: &str,
        seed: u64,
    ) -> Result<CellResult> {
        let model = self.meta_train(formulation, evaluation_condition, seed)?;
        self.evaluate(&model, evaluation_condition)
    }
}

/// The evaluation condition `name` (name or label) of `conditions`. A condition that exists but is
/// only used to meta-train is refused, naming it and listing the evaluation conditions.
pub fn evaluation_condition_of<'a>(
    conditions: &'a ExperimentConditions,
    name: &str,
) -> Result<&'a Condition> {
    let condition = conditions.condition(name)?;
    if condition.role != Role::Evaluation {
        let evaluation: Vec<&str> = conditions.evaluation().map(|c| c.name.as_str()).collect();
        return Err(LearnError::NotEvaluationCondition {
            condition: name.to_string(),
            role: match condition.role {
                Role::MetaTraining => "meta-training",
                Role::Evaluation => "evaluation",
            }
            .to_string(),
            evaluation: evaluation.join(", "),
        });
    }
    Ok(condition)
}

/// The architecture of `formulation` under `config`.
pub fn architecture(formulation: Formulation, config: &crate::config::LearnConfig) -> Architecture {
    Architecture {
        input_dim: formulation.input_names().len(),
        state_dim: formulation.state_dim(),
        basis_per_input: config.basis_per_input,
        hidden: config.hidden_layers.clone(),
    }
}

/// An adaptation window no longer than the support segment (of the flight at `path`) it walks.
fn check_window(
    adaptation: &AdaptationConfig,
    support: &data::Segment,
    path: &Path,
    origin: &Path,
) -> Result<()> {
    if adaptation.window > support.len() {
        return Err(LearnError::Config {
            path: origin.to_path_buf(),
            field: "adaptation.window".to_string(),
            message: format!(
                "{} is more than the {} samples of the support segment of {}",
                adaptation.window,
                support.len(),
                path.display()
            ),
        });
    }
    Ok(())
}

/// Adapted (or trained) parameters that are all finite; otherwise an error naming `cell`.
fn check_finite_parameters(parameters: &[f64], cell: &str, advice: &str) -> Result<()> {
    if parameters.iter().any(|p| !p.is_finite()) {
        return Err(LearnError::NotFinite {
            cell: cell.to_string(),
            message: format!("online adaptation gave non-finite parameters; {advice}"),
        });
    }
    Ok(())
}

fn standardised(standardiser: &Standardiser, batch: Batch) -> Batch {
    Batch {
        inputs: standardiser.apply(&batch.inputs),
        targets: batch.targets,
    }
}

/// Explains `model` over the whole of `log`: first adapted online on the flight's support segment
/// (with the model's own adaptation settings) when `adapt` is set, then [`explain`] over every row.
///
/// [`explain`]: crate::explain()
pub fn explain_flight(
    model: &MetaTrainedModel,
    log: &FlightLog,
    adapt: bool,
    rule: crate::explain::EquationRule,
) -> Result<crate::explain::Explanation> {
    let formulation = model.formulation_for(&format!("explaining over {}", log.path.display()))?;
    let (support, query) = flight_segments(log, formulation)?;
    let support_batch = standardised(&model.standardiser, segment_batch(&support));
    let query_batch = standardised(&model.standardiser, segment_batch(&query));
    let cell = format!("{} model over {}", formulation.name(), log.path.display());
    let mut inputs = support_batch.inputs;
    inputs.extend(query_batch.inputs);
    // The checkpoint itself, before any adaptation: non-finite numbers here come from its
    // standardiser or its meta-trained parameters, never from the adaptation settings.
    let dim = model.architecture.input_dim;
    if let Some(k) = inputs.iter().position(|x| !x.is_finite()) {
        let j = k % dim;
        return Err(LearnError::NotFinite {
            cell,
            message: format!(
                "the checkpoint's standardiser (mean {}, std {} of input '{}') gives standardised inputs that are not finite on this flight, before any adaptation; the adaptation settings are not the cause",
                model.standardiser.mean[j],
                model.standardiser.std[j],
                model.input_name(j)
            ),
        });
    }
    let all_finite = |values: &[f64]| values.iter().all(|v| v.is_finite());
    if !all_finite(&model.architecture.predict(&model.parameters, &inputs)) {
        // The largest standardised input, to tell a standardiser that blows the inputs up from
        // parameters that overflow on ordinary inputs.
        let k = (0..inputs.len())
            .max_by(|&a, &b| inputs[a].abs().total_cmp(&inputs[b].abs()))
            .unwrap_or(0);
        let largest = inputs.get(k).map_or(0.0, |x| x.abs());
        return Err(LearnError::NotFinite {
            cell,
            message: format!(
                "the checkpoint's meta-trained parameters or standardiser give predictions that are not finite on this flight, before any adaptation (largest standardised input: |{}| = {largest:.3e}); the adaptation settings are not the cause",
                model.input_name(k % dim)
            ),
        });
    }
    let parameters = if adapt {
        let adaptation = &model.config.adaptation;
        if adaptation.window > support.len() {
            return Err(LearnError::Flight {
                path: log.path.clone(),
                message: format!(
                    "the support segment has {} samples, fewer than the model's adaptation.window {}",
                    support.len(),
                    adaptation.window
                ),
            });
        }
        let adapted = model.adapt(&support, adaptation);
        // The meta-trained parameters gave finite predictions (checked above): here the
        // adaptation settings are the cause.
        let advice = "the model's adaptation.step or adaptation.lipschitz_weight is too large (the meta-trained parameters give finite predictions before adaptation)";
        check_finite_parameters(&adapted, &cell, advice)?;
        if !all_finite(&model.architecture.predict(&adapted, &inputs)) {
            return Err(LearnError::NotFinite {
                cell,
                message: format!(
                    "online adaptation gave predictions that are not finite; {advice}"
                ),
            });
        }
        adapted
    } else {
        model.parameters.clone()
    };
    let explanation =
        crate::explain::explain(formulation, &model.architecture, &parameters, &inputs, rule);
    let finite = explanation.outputs.iter().all(|output| {
        output
            .inputs
            .iter()
            .all(|input| input.mean_abs_coefficient.is_finite())
    });
    if !finite {
        return Err(LearnError::NotFinite {
            cell,
            message: "the feature-selection coefficients are not finite".to_string(),
        });
    }
    Ok(explanation)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conditions() -> ExperimentConditions {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/conditions.json");
        ExperimentConditions::load(&path).unwrap()
    }

    #[test]
    fn only_evaluation_conditions_name_a_cell() {
        let conditions = conditions();
        let cell = evaluation_condition_of(&conditions, "70psin20").unwrap();
        assert_eq!(cell.name, "70p20sint");
        let error = evaluation_condition_of(&conditions, "nowind").unwrap_err();
        assert!(
            matches!(error, LearnError::NotEvaluationCondition { .. }),
            "{error}"
        );
        assert_eq!(
            error.to_string(),
            "condition 'nowind' is not an evaluation condition (its role is meta-training); \
             the evaluation conditions are: 35wind, 70p20sint, 70wind, 100wind"
        );
        let message = evaluation_condition_of(&conditions, "nope")
            .unwrap_err()
            .to_string();
        assert!(message.contains("unknown condition 'nope'"), "{message}");
    }
}
