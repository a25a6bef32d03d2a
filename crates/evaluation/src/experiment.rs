//! The experiment behind the paper's LeARN columns: meta-train per (formulation, evaluation
//! condition), adapt online on the evaluation flight's support segment, predict its query segment.
//!
//! An [`Experiment`] holds every flight it needs, each read and hashed once ([`Flight`]), and the
//! cells of every formulation × evaluation flight ([`EvaluationCell`]): the support and query
//! segments (cut by the run's [`Segmentation`]: the paper's halves with forward-difference targets
//! on each) that LeARN is adapted and scored on and that the run fits SINDy on, so both methods see
//! the same targets by construction. The meta-training tasks are cut the same way.

mod nested;
mod work;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use data::{Condition, ExperimentConditions, FlightLog};
use faer::Mat;
use learn::{
    AdaptationConfig, Architecture, Batch, CHECKPOINT_FORMAT, CheckedConfig, DataFile,
    FlightTraining, Formulation, InputRange, LearnConfig, LearnError, MetaTrainedModel,
    MetaTrainingOutcome, RangeCoverage, Standardiser, TaskData, TaskGrouping, TrainedOn,
    architecture, check_sampling, from_row_major, mean_squared_error, meta_train,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{EvaluationError, Result};
use crate::flights::{
    Flight, Protocol, evaluation_condition_of, evaluation_flight_path, read_evaluation_flights,
};
use crate::segment::{Segment, Segmentation, flight_segments, segment_batch};

pub use nested::ValidationDetail;
pub use work::{Cells, Spread, SpreadCell, WorkItem, spread_cells};

/// Configuration, conditions, protocol, every flight needed (read once) and the evaluation cells.
pub struct Experiment {
    config: CheckedConfig,
    conditions: ExperimentConditions,
    data_dir: PathBuf,
    protocol: Protocol,
    /// How every flight is cut into segments (evaluation cells and meta-training tasks alike).
    segmentation: Segmentation,
    /// Every flight read, evaluation and meta-training, by the path it was read from.
    flights: BTreeMap<PathBuf, Arc<Flight>>,
    /// The evaluation flights, in table order.
    evaluation: Vec<Arc<Flight>>,
    /// Every formulation × evaluation condition, formulation by formulation in the paper's order,
    /// conditions in table order.
    cells: Vec<Arc<EvaluationCell>>,
}

/// One formulation on one evaluation flight: the segments both methods are fitted or adapted on
/// (support) and scored on (query), cut by the experiment's [`Segmentation`].
#[derive(Debug)]
pub struct EvaluationCell {
    pub formulation: Formulation,
    pub condition: Condition,
    pub flight: Arc<Flight>,
    pub support: Segment,
    pub query: Segment,
}

/// One segment of the evaluation flight: time, targets and the adapted model's predictions.
#[derive(Clone, Debug)]
pub struct SegmentPrediction {
    pub time: Vec<f64>,
    /// ẋ (estimated on this segment alone), samples × I.
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
    #[serde(rename = "adapt_mse")]
    pub adaptation: f64,
    /// The adapted model, frozen, on the query segment.
    #[serde(rename = "gen_mse")]
    pub generalisation: f64,
    /// The meta-trained model before adaptation, on the support segment.
    #[serde(rename = "unadapted_adapt_mse")]
    pub unadapted_adaptation: f64,
    /// The meta-trained model before adaptation, on the query segment.
    #[serde(rename = "unadapted_gen_mse")]
    pub unadapted_generalisation: f64,
    /// The evaluated flight.
    pub evaluation_file: DataFile,
    /// How much of the support segment lies outside the range of the meta-training inputs.
    pub support_coverage: Option<RangeCoverage>,
    /// How much of the query segment lies outside that range (the networks extrapolate there).
    pub query_coverage: Option<RangeCoverage>,
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
    /// `leave-condition-out`) and reads every flight it needs, in parallel; every flight is cut
    /// by `segmentation`.
    pub fn load(
        config: CheckedConfig,
        conditions: ExperimentConditions,
        data_dir: &Path,
        protocol: Option<Protocol>,
        segmentation: Segmentation,
    ) -> Result<Self> {
        let evaluation = read_evaluation_flights(&conditions, data_dir)?;
        Self::load_with(
            config,
            conditions,
            data_dir,
            protocol,
            segmentation,
            &evaluation,
        )
    }

    /// [`Experiment::load`] with the evaluation flights already read (by
    /// [`read_evaluation_flights`], in table order): only the meta-training flights that are not
    /// among them are read.
    pub fn load_with(
        config: CheckedConfig,
        conditions: ExperimentConditions,
        data_dir: &Path,
        protocol: Option<Protocol>,
        segmentation: Segmentation,
        evaluation: &[Arc<Flight>],
    ) -> Result<Self> {
        let protocol = Protocol::resolve(protocol, &conditions, data_dir);
        let evaluated: Vec<&Condition> = conditions.evaluation().collect();
        let mut flights: BTreeMap<PathBuf, Arc<Flight>> = BTreeMap::new();
        if evaluation.len() != evaluated.len() {
            return Err(EvaluationError::Mismatch {
                what: "the evaluation flights".to_string(),
                message: format!(
                    "{} given for {} evaluation conditions",
                    evaluation.len(),
                    evaluated.len()
                ),
            });
        }
        for (condition, flight) in evaluated.iter().zip(evaluation) {
            let path = evaluation_flight_path(&conditions, data_dir, condition);
            if flight.log.path != path {
                return Err(EvaluationError::Mismatch {
                    what: flight.log.path.display().to_string(),
                    message: format!(
                        "given as the evaluation flight of '{}', which is {}",
                        condition.name,
                        path.display()
                    ),
                });
            }
            flights.insert(path, Arc::clone(flight));
        }
        let mut paths: Vec<PathBuf> = Vec::new();
        for condition in &evaluated {
            paths.extend(protocol.training_files(&conditions, data_dir, &condition.name)?);
        }
        paths.sort();
        paths.dedup();
        paths.retain(|path| !flights.contains_key(path));
        let training: Vec<(PathBuf, Arc<Flight>)> = paths
            .par_iter()
            .map(|path| Ok((path.clone(), Arc::new(Flight::read(path, data_dir)?))))
            .collect::<Result<_>>()?;
        flights.extend(training);
        let cells = evaluation_cells(&Formulation::ALL, &evaluated, evaluation, segmentation)?;
        Ok(Self {
            config,
            conditions,
            data_dir: data_dir.to_path_buf(),
            protocol,
            segmentation,
            flights,
            evaluation: evaluation.to_vec(),
            cells,
        })
    }

    /// The protocol every result of this experiment is produced under.
    pub fn protocol(&self) -> Protocol {
        self.protocol
    }

    /// How every flight of this experiment is cut into segments.
    pub fn segmentation(&self) -> Segmentation {
        self.segmentation
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
            .values()
            .map(|flight| flight.file.clone())
            .collect()
    }

    /// The evaluation flight of every evaluation condition, in table order.
    pub fn evaluation_flights(&self) -> &[Arc<Flight>] {
        &self.evaluation
    }

    /// The cell of `formulation` on the evaluation flight of `condition` (its name).
    pub fn cell(&self, formulation: Formulation, condition: &str) -> Result<&Arc<EvaluationCell>> {
        self.cells
            .iter()
            .find(|c| c.formulation == formulation && c.condition.name == condition)
            .ok_or_else(|| EvaluationError::Mismatch {
                what: format!("{} {condition}", formulation.name()),
                message: "not a cell of this experiment".to_string(),
            })
    }

    fn flight(&self, path: &Path) -> Result<&Flight> {
        self.flights
            .get(path)
            .map(|flight| flight.as_ref())
            .ok_or_else(|| EvaluationError::Mismatch {
                what: path.display().to_string(),
                message: "flight was not loaded by this experiment".to_string(),
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
            .map(|path| Ok(self.flight(path)?.file.clone()))
            .collect::<Result<_>>()?;
        Ok(MetaTrainedModel {
            format: CHECKPOINT_FORMAT.to_string(),
            trained_on: TrainedOn::Flights(FlightTraining {
                formulation,
                protocol: self.protocol.name().to_string(),
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
            let (support, query) =
                flight_segments(&self.flight(path)?.log, formulation, self.segmentation)?;
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
        let flights = model.flights().ok_or_else(|| EvaluationError::Mismatch {
            what: format!("evaluation on '{}'", condition.name),
            message: "the model was meta-trained on CSV tasks, not on the flights".to_string(),
        })?;
        if let Some(held_out) = &flights.held_out_condition
            && held_out != &condition.name
        {
            return Err(EvaluationError::Mismatch {
                what: format!("evaluation on '{}'", condition.name),
                message: format!(
                    "the model was meta-trained with '{held_out}' left out, not this condition"
                ),
            });
        }
        let protocol = Protocol::recorded(&flights.protocol)?;
        let cell = self.cell(flights.formulation, &condition.name)?;
        self.evaluate_cell(model, protocol, cell)
    }

    /// [`Experiment::evaluate`] on `cell`, the model meta-trained under `protocol`.
    fn evaluate_cell(
        &self,
        model: &MetaTrainedModel,
        protocol: Protocol,
        cell: &EvaluationCell,
    ) -> Result<CellResult> {
        let (formulation, condition) = (cell.formulation, &cell.condition);
        let (support, query) = (&cell.support, &cell.query);
        let path = &cell.flight.log.path;
        let (raw_support, raw_query) = (segment_batch(support), segment_batch(query));
        let input_names = formulation.input_names();
        let support_batch = standardised(&model.standardiser, raw_support.clone());
        let query_batch = standardised(&model.standardiser, raw_query.clone());
        let architecture = &model.architecture;
        let origin = self.config.origin();
        let adaptation = &self.config.get().adaptation;
        check_window(adaptation, support, path, origin)?;
        let name = format!("{} {}", formulation.name(), condition.name);
        // The meta-trained model before adaptation: when it already gives non-finite numbers the
        // adaptation settings are not the cause.
        let unadapted_adaptation = architecture.loss(
            &model.parameters,
            &support_batch.inputs,
            &support_batch.targets,
        );
        let unadapted_generalisation =
            architecture.loss(&model.parameters, &query_batch.inputs, &query_batch.targets);
        for (what, value) in [
            ("unadapted adaptation MSE", unadapted_adaptation),
            ("unadapted generalisation MSE", unadapted_generalisation),
        ] {
            if !value.is_finite() {
                return Err(not_finite(
                    &name,
                    format!(
                        "the meta-trained model gives a non-finite {what} ({value}) before any adaptation: the meta-trained parameters or the input standardisation, not the adaptation settings, are the cause (see meta_training in {})",
                        origin.display()
                    ),
                ));
            }
        }
        let adapted = model.adapt_on(&raw_support.inputs, &raw_support.targets, adaptation);
        let advice = format!(
            "lower adaptation.step or adaptation.lipschitz_weight in {}",
            origin.display()
        );
        check_finite_parameters(&adapted, &name, &advice)?;
        let support_predictions = model.predict_with(&adapted, &raw_support.inputs);
        let query_predictions = model.predict_with(&adapted, &raw_query.inputs);
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
        let summary = CellSummary {
            formulation,
            condition: condition.name.clone(),
            label: condition.label().to_string(),
            protocol,
            seed: model.seed,
            adaptation: mean_squared_error(&support_predictions, &support_batch.targets),
            generalisation: mean_squared_error(&query_predictions, &query_batch.targets),
            unadapted_adaptation,
            unadapted_generalisation,
            evaluation_file: cell.flight.file.clone(),
            support_coverage,
            query_coverage,
        };
        for (what, value) in [
            ("adaptation MSE", summary.adaptation),
            ("generalisation MSE", summary.generalisation),
        ] {
            if !value.is_finite() {
                return Err(not_finite(
                    &name,
                    format!("the {what} is not finite ({value}); {advice}"),
                ));
            }
        }
        let state_dim = architecture.state_dim;
        let prediction = |segment: &Segment, predictions: &[f64]| SegmentPrediction {
            time: segment.time.clone(),
            targets: segment.targets.clone(),
            predictions: from_row_major(predictions, state_dim),
        };
        Ok(CellResult {
            summary,
            support: prediction(support, &support_predictions),
            query: prediction(query, &query_predictions),
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

/// The cells of `formulations` on every evaluation flight (`flights[k]` of `conditions[k]`), cut
/// by `segmentation`: formulation by formulation, conditions in table order.
pub(crate) fn evaluation_cells(
    formulations: &[Formulation],
    conditions: &[&Condition],
    flights: &[Arc<Flight>],
    segmentation: Segmentation,
) -> Result<Vec<Arc<EvaluationCell>>> {
    let mut cells = Vec::with_capacity(formulations.len() * conditions.len());
    for &formulation in formulations {
        for (condition, flight) in conditions.iter().zip(flights) {
            let (support, query) = flight_segments(&flight.log, formulation, segmentation)?;
            cells.push(Arc::new(EvaluationCell {
                formulation,
                condition: (*condition).clone(),
                flight: Arc::clone(flight),
                support,
                query,
            }));
        }
    }
    Ok(cells)
}

/// A LeARN result that is not a finite number, in the cell named `cell`.
fn not_finite(cell: &str, message: String) -> EvaluationError {
    LearnError::NotFinite {
        cell: cell.to_string(),
        message,
    }
    .into()
}

/// An adaptation window no longer than the support segment (of the flight at `path`) it walks.
fn check_window(
    adaptation: &AdaptationConfig,
    support: &Segment,
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
        }
        .into());
    }
    Ok(())
}

/// Adapted (or trained) parameters that are all finite; otherwise an error naming `cell`.
fn check_finite_parameters(parameters: &[f64], cell: &str, advice: &str) -> Result<()> {
    if parameters.iter().any(|p| !p.is_finite()) {
        return Err(not_finite(
            cell,
            format!("online adaptation gave non-finite parameters; {advice}"),
        ));
    }
    Ok(())
}

/// `batch` with its inputs standardised.
fn standardised(standardiser: &Standardiser, batch: Batch) -> Batch {
    Batch {
        inputs: standardiser.apply(&batch.inputs),
        targets: batch.targets,
    }
}

/// Explains `model` over the whole of `log`: first adapted online on the flight's support segment
/// (cut by `segmentation`, with the model's own adaptation settings) when `adapt` is set, then
/// [`learn::explain`] over every row.
pub fn explain_flight(
    model: &MetaTrainedModel,
    log: &FlightLog,
    segmentation: Segmentation,
    adapt: bool,
    rule: learn::EquationRule,
) -> Result<learn::Explanation> {
    let formulation = model.formulation_for(&format!("explaining over {}", log.path.display()))?;
    let (support, query) = flight_segments(log, formulation, segmentation)?;
    let raw_support = segment_batch(&support);
    let mut inputs = model.standardiser.apply(&raw_support.inputs);
    inputs.extend(model.standardiser.apply(&segment_batch(&query).inputs));
    let cell = format!("{} model over {}", formulation.name(), log.path.display());
    check_unadapted(model, &inputs, &cell)?;
    let parameters = if adapt {
        let adaptation = &model.config.adaptation;
        if adaptation.window > support.len() {
            return Err(EvaluationError::Flight {
                path: log.path.clone(),
                message: format!(
                    "the support segment has {} samples, fewer than the model's adaptation.window {}",
                    support.len(),
                    adaptation.window
                ),
            });
        }
        let adapted = model.adapt_on(&raw_support.inputs, &raw_support.targets, adaptation);
        // The meta-trained parameters gave finite predictions (checked above): here the
        // adaptation settings are the cause.
        let advice = "the model's adaptation.step or adaptation.lipschitz_weight is too large (the meta-trained parameters give finite predictions before adaptation)";
        check_finite_parameters(&adapted, &cell, advice)?;
        if !all_finite(&model.architecture.predict(&adapted, &inputs)) {
            return Err(not_finite(
                &cell,
                format!("online adaptation gave predictions that are not finite; {advice}"),
            ));
        }
        adapted
    } else {
        model.parameters.clone()
    };
    let explanation = learn::explain(formulation, &model.architecture, &parameters, &inputs, rule);
    let finite = explanation.outputs.iter().all(|output| {
        output
            .inputs
            .iter()
            .all(|input| input.mean_abs_coefficient.is_finite())
    });
    if !finite {
        return Err(not_finite(
            &cell,
            "the feature-selection coefficients are not finite".to_string(),
        ));
    }
    Ok(explanation)
}

fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// The checkpoint itself, before any adaptation, on standardised `inputs`: non-finite numbers
/// here come from its standardiser or its meta-trained parameters, never from the adaptation
/// settings.
fn check_unadapted(model: &MetaTrainedModel, inputs: &[f64], cell: &str) -> Result<()> {
    let dim = model.architecture.input_dim;
    let name = |j: usize| {
        model
            .input_names()
            .get(j)
            .cloned()
            .unwrap_or_else(|| "?".to_string())
    };
    if let Some(k) = inputs.iter().position(|x| !x.is_finite()) {
        let j = k % dim;
        return Err(not_finite(
            cell,
            format!(
                "the checkpoint's standardiser (mean {}, std {} of input '{}') gives standardised inputs that are not finite on this flight, before any adaptation; the adaptation settings are not the cause",
                model.standardiser.mean[j],
                model.standardiser.std[j],
                name(j)
            ),
        ));
    }
    if !all_finite(&model.architecture.predict(&model.parameters, inputs)) {
        // The largest standardised input, to tell a standardiser that blows the inputs up from
        // parameters that overflow on ordinary inputs.
        let k = (0..inputs.len())
            .max_by(|&a, &b| inputs[a].abs().total_cmp(&inputs[b].abs()))
            .unwrap_or(0);
        let largest = inputs.get(k).map_or(0.0, |x| x.abs());
        return Err(not_finite(
            cell,
            format!(
                "the checkpoint's meta-trained parameters or standardiser give predictions that are not finite on this flight, before any adaptation (largest standardised input: |{}| = {largest:.3e}); the adaptation settings are not the cause",
                name(k % dim)
            ),
        ));
    }
    Ok(())
}
