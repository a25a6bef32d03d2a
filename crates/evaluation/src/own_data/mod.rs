//! LeARN on your own data next to the baselines, on the same rows: what `learn evaluate` reports
//! ([`compare_on_recording`]) and the worked example's learning curve ([`example`]); reading the
//! CSV tasks and recordings LeARN meta-trains, adapts and explains on ([`read_tasks`],
//! [`read_recording`], [`recording`]).
//!
//! A model of CSV tasks is adapted online on the support rows of a new recording
//! ([`learn::evaluate_recording`]); SINDy is fitted on the same support rows, with the same
//! targets (the model's derivative, estimated on the support rows alone), and both are scored on
//! the same query rows. MSE: mean over all samples and all states, in the units of the targets.

pub mod example;
mod family;
mod tasks;

use std::ops::Range;

use data::TaskTable;
use faer::Mat;
use learn::{MetaTrainedModel, RecordingEvaluation};
use serde::Serialize;
use sindy::{FeatureLibrary, OptimizerSpec, SindyModel, SindyParams};

use crate::error::{EvaluationError, Result};

pub use family::{FamilyConfig, ParameterRange, SimulatedTask, TaskParameters, simulate_task};
pub use tasks::{check_interval, data_files, read_recording, read_tasks, recording};

/// Adaptation (support rows) and generalisation (query rows) MSE of one method.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Scores {
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
}

/// LeARN and SINDy on the same rows of one recording.
#[derive(Clone, Debug)]
pub struct RecordingComparison {
    /// The meta-trained model adapted online on the support rows.
    pub learn: Scores,
    /// The meta-trained model before adaptation.
    pub learn_unadapted: Scores,
    /// SINDy fitted on the support rows.
    pub sindy: Scores,
    pub sindy_model: SindyModel,
    pub evaluation: RecordingEvaluation,
}

/// Row-major values as a matrix of `columns` columns.
pub(crate) fn matrix(values: &[f64], columns: usize) -> Mat<f64> {
    Mat::from_fn(values.len() / columns, columns, |i, j| {
        values[i * columns + j]
    })
}

/// The SINDy settings a comparison fits with (those of `learn sindy`); the names and the
/// derivative are the model's.
#[derive(Clone, Debug)]
pub struct SindySettings {
    pub library: FeatureLibrary,
    pub optimizer: OptimizerSpec,
}

impl SindySettings {
    /// The SINDy fit of these settings for the columns and derivative of a model of CSV tasks.
    pub fn params(&self, columns: &learn::ColumnTraining) -> SindyParams {
        let states: Vec<&str> = columns.state.iter().map(String::as_str).collect();
        let controls: Vec<&str> = columns.control.iter().map(String::as_str).collect();
        SindyParams::new(&states, &controls)
            .library(self.library.clone())
            .optimizer(self.optimizer)
            .derivative(columns.derivative)
    }
}

/// The MSE of predictions (a matrix) against row-major targets.
pub(crate) fn mse(predictions: &Mat<f64>, targets: &[f64]) -> f64 {
    let columns = predictions.ncols();
    let target = matrix(targets, columns);
    sindy::mean_squared_error(predictions.as_ref(), target.as_ref())
}

/// SINDy (`sindy`, whose states and controls must be the model's columns) fitted on the rows of
/// `fit`, scored on `fit` and on `query`. Refuses fewer rows than features (as `learn sindy`).
pub(crate) fn sindy_scores(
    sindy: &SindyParams,
    library: &FeatureLibrary,
    fit: &learn::Batch,
    query: &learn::Batch,
    dims: (usize, usize),
    rows_text: &str,
) -> Result<(Scores, SindyModel)> {
    let (inputs, states) = dims;
    let support_inputs = matrix(&fit.inputs, inputs);
    let rows = support_inputs.nrows();
    let features = library.feature_count(inputs);
    if rows < features {
        return Err(EvaluationError::Mismatch {
            what: rows_text.to_string(),
            message: format!(
                "{rows} rows, fewer than the {features} features of the SINDy library: the comparison needs at least one row per feature (choose more rows or a smaller --library)"
            ),
        });
    }
    let model = sindy.fit_matrices(
        support_inputs.as_ref(),
        matrix(&fit.targets, states).as_ref(),
    )?;
    let score = |batch: &learn::Batch| -> Result<f64> {
        let predictions = model.predict_inputs(matrix(&batch.inputs, inputs).as_ref())?;
        Ok(mse(&predictions, &batch.targets))
    };
    let scores = Scores {
        adaptation: score(fit)?,
        generalisation: score(query)?,
    };
    Ok((scores, model))
}

/// Adapts `model` on `support` rows of `recording` and scores it on `query` rows, next to SINDy
/// (`settings`: the library and optimizer of `learn sindy`, with the model's names and
/// derivative) fitted on the same support rows. Errors name the file and the rows.
pub fn compare_on_recording(
    model: &MetaTrainedModel,
    recording: &TaskTable,
    support: Range<usize>,
    query: Range<usize>,
    settings: &SindySettings,
) -> Result<RecordingComparison> {
    let columns = learn::column_training(model, "evaluation")?;
    let evaluation = tasks::evaluate_on(model, recording, support.clone(), query)?;
    let sindy = settings.params(columns);
    let (inputs, states) = (
        columns.state.len() + columns.control.len(),
        columns.state.len(),
    );
    let rows_text = format!(
        "{}: --support-rows {}:{}",
        recording.path.display(),
        support.start,
        support.end
    );
    let (sindy_scores, sindy_model) = sindy_scores(
        &sindy,
        &settings.library,
        &evaluation.support,
        &evaluation.query,
        (inputs, states),
        &rows_text,
    )?;
    for (what, value) in [
        ("SINDy's adaptation MSE", sindy_scores.adaptation),
        ("SINDy's generalisation MSE", sindy_scores.generalisation),
    ] {
        if !value.is_finite() {
            return Err(EvaluationError::Mismatch {
                what: rows_text.clone(),
                message: format!("{what} is not finite ({value}): rescale the data?"),
            });
        }
    }
    Ok(RecordingComparison {
        learn: Scores {
            adaptation: evaluation.adaptation,
            generalisation: evaluation.generalisation,
        },
        learn_unadapted: Scores {
            adaptation: evaluation.unadapted_adaptation,
            generalisation: evaluation.unadapted_generalisation,
        },
        sindy: sindy_scores,
        sindy_model,
        evaluation,
    })
}
