//! The paper's SINDy baseline as one call: fit on a support segment, predict on it and on a query
//! segment, report both mean squared errors.

use data::{Derivative, FlightLog, Formulation, Segment, SplitSpec};
use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::error::{Result, shape};
use crate::library::{FeatureLibrary, LibrarySpec};
use crate::model::{SindyModel, SindyParams, mean_squared_error};
use crate::optimizer::OptimizerSpec;

/// What a SINDy baseline fits: the library and the optimizer (serialisable, e.g. in a run config).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SindyConfig {
    pub library: LibrarySpec,
    pub optimizer: OptimizerSpec,
}

impl SindyConfig {
    /// The protocol that reproduces the paper's SINDy columns: Fourier library with one frequency on
    /// X = [x, u], no constant; STLSQ threshold 0.2, alpha 0.05, 20 iterations.
    pub fn paper() -> Self {
        Self {
            library: LibrarySpec::Fourier { frequencies: 1 },
            optimizer: OptimizerSpec::stlsq(0.2),
        }
    }
}

/// A model fitted on a support segment and its predictions on support and query.
#[derive(Clone, Debug)]
pub struct SegmentEvaluation {
    pub model: SindyModel,
    /// Predicted ẋ on the support segment, one row per sample.
    pub support_prediction: Mat<f64>,
    /// Predicted ẋ on the query segment (no refit), one row per sample.
    pub query_prediction: Mat<f64>,
    /// MSE against the support segment's targets: mean over samples and state dimensions
    /// (the paper's "adapt" error).
    pub support_mse: f64,
    /// MSE against the query segment's targets (the paper's "gen" error).
    pub query_mse: f64,
}

/// Fits `config` on `support` (its states, controls and targets as built by the data crate),
/// then predicts ẋ on `support` and on `query` without refitting.
pub fn fit_and_evaluate(
    config: &SindyConfig,
    support: &Segment,
    query: &Segment,
) -> Result<SegmentEvaluation> {
    if support.formulation != query.formulation {
        return Err(shape(
            "segments",
            format!(
                "support is {}, query is {}",
                support.formulation.name(),
                query.formulation.name()
            ),
        ));
    }
    let formulation = support.formulation;
    let params = SindyParams::new(&formulation.state_names(), &formulation.control_names())
        .library(FeatureLibrary::from_spec(&config.library)?)
        .optimizer(config.optimizer);
    let model = params.fit_matrices(support.inputs().as_ref(), support.targets.as_ref())?;
    let support_prediction = model.predict_inputs(support.inputs().as_ref())?;
    let query_prediction = model.predict_inputs(query.inputs().as_ref())?;
    Ok(SegmentEvaluation {
        support_mse: mean_squared_error(support_prediction.as_ref(), support.targets.as_ref()),
        query_mse: mean_squared_error(query_prediction.as_ref(), query.targets.as_ref()),
        model,
        support_prediction,
        query_prediction,
    })
}

/// Cuts `log` with `split`, builds both segments of `formulation` (each with its own derivative
/// estimate) and runs [`fit_and_evaluate`]. The paper's cell is
/// `evaluate_flight(&SindyConfig::paper(), log, formulation, SplitSpec::Halves, Derivative::Forward)`.
pub fn evaluate_flight(
    config: &SindyConfig,
    log: &FlightLog,
    formulation: Formulation,
    split: SplitSpec,
    derivative: Derivative,
) -> Result<SegmentEvaluation> {
    let rows = split.split(log.len())?;
    let support = formulation.segment(log, rows.support, derivative)?;
    let query = formulation.segment(log, rows.query, derivative)?;
    fit_and_evaluate(config, &support, &query)
}
