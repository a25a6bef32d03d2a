//! LeARN on any multi-task set: meta-training on recordings of one system under different
//! conditions ([`meta_train_tasks`]), online adaptation on rows of a new recording and prediction of
//! others ([`evaluate_recording`]), explanation over a recording ([`explain_recording`]). The
//! recordings are in memory ([`Recording`]: named columns, one sampling interval); reading them
//! from CSV files, and checking a recording's sampling interval against a model's, is the
//! `evaluation` crate's (`evaluation::own_data`).
//!
//! The same model and algorithms as the paper's: inputs X = [x, u] (the state then control
//! columns), outputs ẋ, the architecture of the paper's rule (I + U inputs, P·(I+U) basis
//! functions, I·P·(I+U) selection values), exact second-order MAML, online adaptation with the
//! Lipschitz regulariser. As in the paper, each task is cut into a support half (the first
//! ⌊n/2⌋ rows) and a query half, and targets are estimated on each segment separately, so that no
//! target of one segment uses a sample of the other. Two things differ from the flight models,
//! both recorded in the checkpoint: inputs are always z-scored when `standardise_inputs` is set
//! (as for flights) and targets are divided by their standard deviation over the meta-training
//! tasks (`trained_on.target_scale`), so that the paper's steps suit data in any units.

use std::ops::Range;
use std::path::Path;

use crate::columns::{ColumnSpec, ColumnTraining, TaskConfig, TaskRows, TaskSource};
use crate::config::{TaskGrouping, limits};
use crate::error::{LearnError, Result};
use crate::explain::{EquationRule, Explanation, ModelNames, explain_named};
use crate::maml::Batch;
use crate::model::{CHECKPOINT_FORMAT, DataFile, MetaTrainedModel, TrainedOn};
use crate::network::mean_squared_error;
use crate::standardiser::{InputRange, Standardiser};
use crate::train::{TaskData, check_sampling, meta_train_observed};

/// One recording (a task, or a new recording to adapt on) in memory: the columns of a
/// [`ColumnSpec`] in its order (the states, then the controls), one value per row, uniformly
/// sampled.
#[derive(Clone, Copy, Debug)]
pub struct Recording<'a> {
    /// The task's name: a file name, or `file[column=value]` for a run of a task column.
    pub name: &'a str,
    /// The file it was read from (named in errors).
    pub path: &'a Path,
    /// One column per state, then per control, each one value per row.
    pub columns: &'a [Vec<f64>],
    /// The sampling interval, seconds.
    pub interval: f64,
}

impl Recording<'_> {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }
}

/// Raw inputs X = [x, u] (row-major) and targets ẋ of rows `rows` of `recording` (holding the
/// columns of `spec`), the targets estimated with `spec.derivative` on those rows alone.
/// `what` names the rows in errors (e.g. `support rows 0:100`).
pub fn segment_data(
    recording: Recording<'_>,
    spec: &ColumnSpec,
    rows: Range<usize>,
    what: &str,
) -> Result<Batch> {
    let fail = |message: String| LearnError::Task {
        path: recording.path.to_path_buf(),
        message: format!("{what}: {message}"),
    };
    let available = recording.rows();
    if rows.start >= rows.end || rows.end > available {
        return Err(fail(format!(
            "rows {}:{} do not lie within the {available} data rows of task '{}' (rows are counted from 0, the end excluded)",
            rows.start, rows.end, recording.name
        )));
    }
    let needed = spec.derivative.min_samples().max(2);
    if rows.len() < needed {
        return Err(fail(format!(
            "{} rows, fewer than the {needed} the {} derivative needs",
            rows.len(),
            spec.derivative
        )));
    }
    let columns = recording.columns;
    let dim = columns.len();
    let mut inputs = Vec::with_capacity(rows.len() * dim);
    for row in rows.clone() {
        inputs.extend(columns.iter().map(|column| column[row]));
    }
    let states = spec.state.len();
    let derivatives = columns[..states]
        .iter()
        .map(|column| {
            spec.derivative
                .apply(&column[rows.clone()], recording.interval)
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let mut targets = Vec::with_capacity(rows.len() * states);
    for k in 0..rows.len() {
        targets.extend(derivatives.iter().map(|column| column[k]));
    }
    if let Some(k) = targets.iter().position(|t| !t.is_finite()) {
        return Err(fail(format!(
            "the derivative of '{}' is not finite at row {} (time steps too small?)",
            spec.state[k % states],
            rows.start + k / states
        )));
    }
    Ok(Batch { inputs, targets })
}

/// The support (first ⌊n/2⌋ rows) and query (the rest) data of a meta-training task.
fn task_halves(task: Recording<'_>, spec: &ColumnSpec) -> Result<(Batch, Batch)> {
    let n = task.rows();
    let needed = spec.derivative.min_samples().max(2);
    if n / 2 < needed {
        return Err(LearnError::Task {
            path: task.path.to_path_buf(),
            message: format!(
                "task '{}' has {n} data rows: meta-training cuts each task into a support and a query half of at least {needed} rows each (the {} derivative), so at least {} rows are needed",
                task.name,
                spec.derivative,
                2 * needed
            ),
        });
    }
    let support = segment_data(task, spec, 0..n / 2, "support half")?;
    let query = segment_data(task, spec, n / 2..n, "query half")?;
    Ok((support, query))
}

/// Per column of row-major `values` (`dim` columns): the population standard deviation, 1 where
/// it is zero or not finite.
fn column_scale<'a>(batches: impl Iterator<Item = &'a [f64]> + Clone, dim: usize) -> Vec<f64> {
    Standardiser::fit(batches, dim)
        .std
        .into_iter()
        .map(|s| if s.is_finite() && s > 0.0 { s } else { 1.0 })
        .collect()
}

/// What [`meta_train_tasks`] reads: the tasks, where they came from and their files.
pub struct TaskSet<'a> {
    pub source: &'a TaskSource,
    pub spec: &'a ColumnSpec,
    /// The tasks, each with the columns of `spec`, all sampled at one interval.
    pub tasks: &'a [Recording<'a>],
    /// The files read, with their SHA-256, recorded in the model.
    pub files: Vec<DataFile>,
}

/// Meta-trains a model on `set` with `config` (batch sizes it does not name fitted to the tasks),
/// calling `iteration_done` after each meta-iteration. Errors name the task file, or the
/// configuration file and field.
pub fn meta_train_tasks(
    set: TaskSet<'_>,
    config: &TaskConfig,
    iteration_done: &dyn Fn(usize),
) -> Result<MetaTrainedModel> {
    let config_error = |field: &str, message: String| LearnError::Config {
        path: config.origin_path(),
        field: field.to_string(),
        message,
    };
    set.spec.check().map_err(|message| LearnError::Mismatch {
        what: "columns".to_string(),
        message,
    })?;
    if set.tasks.is_empty() {
        return Err(LearnError::Mismatch {
            what: "meta-training".to_string(),
            message: "no tasks".to_string(),
        });
    }
    if config.get().meta_training.tasks == TaskGrouping::Condition {
        return Err(config_error(
            "meta_training.tasks",
            "'condition' pools the flights of a wind condition; each CSV task is one task: use 'flight'".to_string(),
        ));
    }
    let raw: Vec<(Batch, Batch)> = set
        .tasks
        .iter()
        .map(|&task| task_halves(task, set.spec))
        .collect::<Result<_>>()?;
    let mut model = untrained_model(&set, config, &raw)?;
    let task_data: Vec<TaskData> = set
        .tasks
        .iter()
        .zip(raw)
        .map(|(task, (support, query))| TaskData {
            name: task.name.to_string(),
            support: model_batch(&model, support),
            query: model_batch(&model, query),
        })
        .collect();
    let meta = &model.config.meta_training;
    check_sampling(meta, &task_data, model.architecture.input_dim)
        .map_err(|(field, message)| config_error(field, message))?;
    let outcome = meta_train_observed(
        &model.architecture,
        model.architecture.initial_parameters(model.seed),
        &task_data,
        meta,
        model.seed,
        iteration_done,
    )
    .map_err(|error| match error {
        LearnError::Diverged { iteration, loss } => config_error(
            "meta_training.outer_step",
            format!(
                "meta-training diverged at iteration {iteration} (loss {loss}); lower meta_training.outer_step or meta_training.inner_step"
            ),
        ),
        other => other,
    })?;
    model.parameters = outcome.parameters;
    model.meta_loss_history = outcome.meta_loss_history;
    Ok(model)
}

/// The model before meta-training (no parameters yet): the settings fitted to the tasks, the
/// input standardiser and target scales of their raw `(support, query)` data, the architecture
/// of the paper's rule (refused beyond [`limits::PARAMETERS`]) and what it is trained on.
fn untrained_model(
    set: &TaskSet<'_>,
    config: &TaskConfig,
    raw: &[(Batch, Batch)],
) -> Result<MetaTrainedModel> {
    let (spec, tasks) = (set.spec, set.tasks);
    let dim = spec.state.len() + spec.control.len();
    let settings = config.fit_to(
        tasks.len(),
        tasks.iter().map(|t| t.rows() / 2).min().unwrap_or(0),
        tasks
            .iter()
            .map(|t| t.rows() - t.rows() / 2)
            .min()
            .unwrap_or(0),
    );
    let all_inputs = raw
        .iter()
        .flat_map(|(s, q)| [s.inputs.as_slice(), q.inputs.as_slice()]);
    let standardiser = if settings.standardise_inputs {
        Standardiser::fit(all_inputs.clone(), dim)
    } else {
        Standardiser::identity(dim)
    }
    .with_range(InputRange::spanned(all_inputs, dim), settings.clamp_inputs);
    let target_scale = column_scale(
        raw.iter()
            .flat_map(|(s, q)| [s.targets.as_slice(), q.targets.as_slice()]),
        spec.state.len(),
    );
    let architecture = spec.architecture(&settings);
    if architecture.parameter_count() > limits::PARAMETERS {
        return Err(LearnError::Config {
            path: config.origin_path(),
            field: "hidden_layers".to_string(),
            message: format!(
                "the networks for {} inputs and {} outputs would have {} parameters, more than {}",
                architecture.input_dim,
                architecture.state_dim,
                architecture.parameter_count(),
                limits::PARAMETERS
            ),
        });
    }
    let trained_on = ColumnTraining {
        time: spec.time.clone(),
        state: spec.state.clone(),
        control: spec.control.clone(),
        derivative: spec.derivative,
        sampling_interval: tasks[0].interval,
        target_scale,
        source: set.source.clone(),
        tasks: tasks
            .iter()
            .map(|t| TaskRows {
                name: t.name.to_string(),
                rows: t.rows(),
            })
            .collect(),
    };
    Ok(MetaTrainedModel {
        format: CHECKPOINT_FORMAT.to_string(),
        trained_on: TrainedOn::Columns(trained_on),
        seed: settings.seed,
        config: settings,
        parameters: Vec::new(),
        standardiser,
        architecture,
        data_files: set.files.clone(),
        meta_loss_history: Vec::new(),
    })
}

/// Raw data in the units the networks learn: standardised inputs, scaled targets.
fn model_batch(model: &MetaTrainedModel, raw: Batch) -> Batch {
    Batch {
        inputs: model.standardiser.apply(&raw.inputs),
        targets: model.scaled_targets(&raw.targets),
    }
}

/// The adapted model on the support rows and on the query rows of a recording.
#[derive(Clone, Debug)]
pub struct RecordingEvaluation {
    pub support_rows: Range<usize>,
    pub query_rows: Range<usize>,
    /// The model adapted online on the support rows, on those rows.
    pub adaptation: f64,
    /// The same adapted model, frozen, on the query rows.
    pub generalisation: f64,
    /// The meta-trained model before adaptation, on the support rows.
    pub unadapted_adaptation: f64,
    /// The meta-trained model before adaptation, on the query rows.
    pub unadapted_generalisation: f64,
    /// θ after adaptation.
    pub adapted_parameters: Vec<f64>,
    /// Raw inputs and targets of the support rows (for a baseline fitted on the same data).
    pub support: Batch,
    /// Raw inputs and targets of the query rows.
    pub query: Batch,
}

/// The columns of a model of CSV tasks, or an error naming `what` needs them.
pub fn column_training<'a>(model: &'a MetaTrainedModel, what: &str) -> Result<&'a ColumnTraining> {
    match &model.trained_on {
        TrainedOn::Columns(columns) => Ok(columns),
        TrainedOn::Flights(flights) => Err(LearnError::Mismatch {
            what: what.to_string(),
            message: format!(
                "needs a model meta-trained on CSV tasks (learn meta-train --tasks); this one is a flight model of formulation '{}'",
                flights.formulation.name()
            ),
        }),
    }
}

/// Adapts `model` online on `support` rows of `recording` (holding the model's columns, sampled at
/// the interval of its tasks), in time order with the model's adaptation settings, and scores it
/// there and, frozen, on `query` rows. Errors name the file: rows outside the recording or too few
/// for the derivative or the adaptation window, non-finite results.
pub fn evaluate_recording(
    model: &MetaTrainedModel,
    recording: Recording<'_>,
    support: Range<usize>,
    query: Range<usize>,
) -> Result<RecordingEvaluation> {
    let columns = column_training(model, "evaluation")?;
    let spec = columns.spec();
    let support_data = segment_data(
        recording,
        &spec,
        support.clone(),
        &format!("support rows {}:{}", support.start, support.end),
    )?;
    let query_data = segment_data(
        recording,
        &spec,
        query.clone(),
        &format!("query rows {}:{}", query.start, query.end),
    )?;
    let adaptation = &model.config.adaptation;
    if adaptation.window > support.len() {
        return Err(LearnError::Task {
            path: recording.path.to_path_buf(),
            message: format!(
                "support rows {}:{}: {} rows, fewer than the model's adaptation.window {}",
                support.start,
                support.end,
                support.len(),
                adaptation.window
            ),
        });
    }
    let adapted = model.adapt_on(&support_data.inputs, &support_data.targets, adaptation);
    let mse = |parameters: &[f64], data: &Batch| {
        mean_squared_error(&model.predict_with(parameters, &data.inputs), &data.targets)
    };
    let evaluation = RecordingEvaluation {
        adaptation: mse(&adapted, &support_data),
        generalisation: mse(&adapted, &query_data),
        unadapted_adaptation: mse(&model.parameters, &support_data),
        unadapted_generalisation: mse(&model.parameters, &query_data),
        support_rows: support,
        query_rows: query,
        adapted_parameters: adapted,
        support: support_data,
        query: query_data,
    };
    for (name, value) in [
        (
            "meta-trained model's support MSE",
            evaluation.unadapted_adaptation,
        ),
        ("adaptation MSE", evaluation.adaptation),
        ("generalisation MSE", evaluation.generalisation),
    ] {
        if !value.is_finite() {
            return Err(LearnError::NotFinite {
                cell: recording.path.display().to_string(),
                message: format!(
                    "the {name} is not finite ({value}); the model's adaptation.step may be too large"
                ),
            });
        }
    }
    Ok(evaluation)
}

/// Explains a model of CSV tasks over every row of `recording`: first adapted online on `support`
/// rows when given (the paper's explanation of an adapted model), then [`explain_named`] with the
/// coefficients in the units of the targets.
pub fn explain_recording(
    model: &MetaTrainedModel,
    recording: Recording<'_>,
    support: Option<Range<usize>>,
    rule: EquationRule,
) -> Result<Explanation> {
    let columns = column_training(model, "explanation")?;
    let parameters = match support {
        Some(rows) => evaluate_recording(model, recording, rows.clone(), rows)?.adapted_parameters,
        None => model.parameters.clone(),
    };
    let dim = recording.columns.len();
    let mut raw = Vec::with_capacity(recording.rows() * dim);
    for row in 0..recording.rows() {
        raw.extend(recording.columns.iter().map(|column| column[row]));
    }
    let names = ModelNames {
        inputs: columns.input_names(),
        outputs: columns.output_names(),
        output_scale: Some(columns.target_scale.clone()),
    };
    let inputs = model.standardiser.apply(&raw);
    let explanation = explain_named(&names, &model.architecture, &parameters, &inputs, rule);
    let finite = explanation.outputs.iter().all(|output| {
        output
            .inputs
            .iter()
            .all(|i| i.mean_abs_coefficient.is_finite())
    });
    if !finite {
        return Err(LearnError::NotFinite {
            cell: recording.path.display().to_string(),
            message: "the feature-selection coefficients are not finite".to_string(),
        });
    }
    Ok(explanation)
}
