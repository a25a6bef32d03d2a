//! Variants of the SINDy column evaluated on the paper's protocol: a library and a regression whose
//! penalty is chosen inside the support segment, scored on support (adapt) and query (gen).

use crate::segment::Segment;

use serde::{Deserialize, Serialize};

use sindy::{
    EnsemblePrediction, Mat, MatRef, RegressionFit, RegressionSpec, Result, mean_squared_error,
    shape,
};

use crate::causal_library::CausalLibrary;

/// A library and a regression (serialisable, e.g. in `experiments/variants.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LibraryRegression {
    pub library: CausalLibrary,
    pub regression: RegressionSpec,
}

/// A model's predictions of the support and query segments (samples × outputs), scored against
/// their targets.
#[derive(Clone, Debug)]
pub struct SegmentPredictions {
    pub support_prediction: Mat<f64>,
    pub query_prediction: Mat<f64>,
    /// MSE on the support segment (adapt) and on the query segment (gen).
    pub adaptation: f64,
    pub generalisation: f64,
    /// The ensemble band on both segments, when bagged.
    pub support_band: Option<EnsemblePrediction>,
    pub query_band: Option<EnsemblePrediction>,
}

impl SegmentPredictions {
    /// Predictions scored by their mean squared error against the targets; no band.
    pub fn scored(
        support_prediction: Mat<f64>,
        query_prediction: Mat<f64>,
        support_targets: MatRef<'_, f64>,
        query_targets: MatRef<'_, f64>,
    ) -> Self {
        Self {
            adaptation: mean_squared_error(support_prediction.as_ref(), support_targets),
            generalisation: mean_squared_error(query_prediction.as_ref(), query_targets),
            support_prediction,
            query_prediction,
            support_band: None,
            query_band: None,
        }
    }
}

/// A variant fitted on a support segment and its predictions on support and query.
#[derive(Clone, Debug)]
pub struct VariantEvaluation {
    pub feature_names: Vec<String>,
    pub fit: RegressionFit,
    pub predictions: SegmentPredictions,
}

impl LibraryRegression {
    /// Checks the library ([`CausalLibrary::validate`]) and the regression
    /// ([`RegressionSpec::validate`]); errors are [`sindy::SindyError::Field`] naming the field,
    /// e.g. `regression.penalty.lambdas` or `library.control_lags`.
    pub fn validate(&self) -> Result<()> {
        self.library.validate().map_err(|e| e.within("library"))?;
        self.regression
            .validate()
            .map_err(|e| e.within("regression"))
    }

    /// Builds the library on each segment, fits on the support segment (choosing the penalty
    /// there), predicts both.
    pub fn evaluate(
        &self,
        support: &Segment,
        query: &Segment,
        seed: u64,
    ) -> Result<VariantEvaluation> {
        if support.formulation != query.formulation {
            return Err(shape("segments", "support and query formulations differ"));
        }
        let (support_theta, names) = self.library.features(support)?;
        let (query_theta, _) = self.library.features(query)?;
        evaluate_features(
            &self.regression,
            names,
            support_theta.as_ref(),
            support.targets.as_ref(),
            query_theta.as_ref(),
            query.targets.as_ref(),
            seed,
        )
    }
}

/// Fits `regression` on the support features and targets, predicts support and query.
pub fn evaluate_features(
    regression: &RegressionSpec,
    feature_names: Vec<String>,
    support_theta: MatRef<'_, f64>,
    support_targets: MatRef<'_, f64>,
    query_theta: MatRef<'_, f64>,
    query_targets: MatRef<'_, f64>,
    seed: u64,
) -> Result<VariantEvaluation> {
    if support_theta.ncols() != query_theta.ncols() {
        return Err(shape(
            "variant features",
            format!(
                "support has {} features, query {}",
                support_theta.ncols(),
                query_theta.ncols()
            ),
        ));
    }
    let fit = regression.fit(support_theta, support_targets, seed)?;
    let predictions = SegmentPredictions {
        support_band: fit.ensemble(support_theta),
        query_band: fit.ensemble(query_theta),
        ..SegmentPredictions::scored(
            fit.predict(support_theta),
            fit.predict(query_theta),
            support_targets,
            query_targets,
        )
    };
    Ok(VariantEvaluation {
        feature_names,
        fit,
        predictions,
    })
}
