//! The variants as methods ([`crate::Method`]): each variant of a file evaluated on one cell and
//! seed by the [`crate::Runner`], in declaration order (a `select` or `average` takes the outcomes
//! of variants before it), and `make reproduce`'s extra columns ([`reproduce_columns`]).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use crate::experiment::{EvaluationCell, Experiment};
use crate::flights::Flight;
use crate::runner::{Fitted, Method, Models, Outcome, Runner, Trial};
use crate::segment::{Segment, SegmentModel};
use crate::sindy_variant::{SegmentPredictions, VariantEvaluation, evaluate_features};
use learn::variants::learned_features;
use learn::{Formulation, MetaTrainedModel};
use sindy::Mat;

use super::checks::learned_basis_config;
use super::combinators::{average, ensemble_mean, select};
use super::schema::{
    CheckedVariants, LearnedBasisSpec, VariantKind, VariantSpec, VariantsConfig,
    ensemble_member_seeds,
};
use crate::error::{EvaluationError, Result};

impl LearnedBasisSpec {
    /// Features of both segments from the frozen networks (and the fixed library), regression
    /// fitted and its penalty chosen on the support segment.
    pub fn evaluate(
        &self,
        model: &MetaTrainedModel,
        support: &Segment,
        query: &Segment,
        seed: u64,
    ) -> Result<VariantEvaluation> {
        let features = |segment: &Segment| -> Result<(Mat<f64>, Vec<String>)> {
            let (learned, learned_names) =
                learned_features(model, &segment.inputs(), self.features);
            let Some(library) = &self.library else {
                return Ok((learned, learned_names));
            };
            let (fixed, mut names) = library.features(segment)?;
            names.extend(learned_names);
            let theta = Mat::from_fn(segment.len(), fixed.ncols() + learned.ncols(), |i, j| {
                if j < fixed.ncols() {
                    fixed[(i, j)]
                } else {
                    learned[(i, j - fixed.ncols())]
                }
            });
            Ok((theta, names))
        };
        let (support_theta, names) = features(support)?;
        let (query_theta, _) = features(query)?;
        Ok(evaluate_features(
            &self.regression,
            names,
            support_theta.as_ref(),
            support.targets.as_ref(),
            query_theta.as_ref(),
            query.targets.as_ref(),
            seed,
        )?)
    }
}

/// The extra columns `make reproduce` shows: the `reproduce` variants of the variants file
/// `config` on `cell`, with the first seed of that file, the run's meta-trained LeARN `model`
/// serving every variant that asks for the networks (`read` refused ensembles in these columns).
pub fn reproduce_columns(
    config: &VariantsConfig,
    cell: &EvaluationCell,
    model: &MetaTrainedModel,
) -> Result<BTreeMap<String, report::Mse>> {
    let variants = config.reproduce_variants();
    let seed = config.seeds[0];
    let runner = Runner::new(variants.iter().map(|v| v as &dyn Method), None);
    let mut models = Models::new(cell, None).with(seed, Arc::new(model.clone()));
    let outcomes = runner.evaluate(cell, seed, &mut models)?;
    Ok(variants
        .iter()
        .zip(outcomes)
        .filter(|(spec, _)| config.reproduce.contains(&spec.name))
        .map(|(spec, outcome)| {
            (
                spec.name.clone(),
                report::Mse {
                    adaptation: outcome.predictions.adaptation,
                    generalisation: outcome.predictions.generalisation,
                },
            )
        })
        .collect())
}

/// The LeARN experiment of the learned-basis variants: the run's, with the variants file's
/// `learn_overrides`.
pub(crate) fn learned_basis_experiment(
    config: &CheckedVariants,
    data_dir: &Path,
    evaluation: &[Arc<Flight>],
) -> Result<Experiment> {
    let run = &config.run;
    Experiment::load_with(
        learned_basis_config(config)?,
        run.conditions.clone(),
        data_dir,
        run.protocol,
        run.segmentation(),
        evaluation,
    )
}

/// A variant on one cell and seed. The networks it asks for must not have read the query segment
/// (the reproduce run's leave the evaluation flight out entirely); errors name the variant.
impl Method for VariantSpec {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs_meta_training(&self) -> bool {
        self.kind.needs_meta_training()
    }

    fn evaluate(&self, trial: &mut Trial<'_, '_>) -> Result<Outcome> {
        self.outcome(trial).map_err(|error| match error {
            error @ EvaluationError::Mismatch { .. } => error,
            error => EvaluationError::Mismatch {
                what: format!("variant '{}'", self.name),
                message: error.to_string(),
            },
        })
    }
}

impl VariantSpec {
    /// [`Method::evaluate`], its errors not yet named.
    fn outcome(&self, trial: &mut Trial<'_, '_>) -> Result<Outcome> {
        let (cell, seed) = (trial.cell, trial.seed);
        let (support, query) = (&cell.support, &cell.query);
        Ok(match &self.kind {
            VariantKind::Library(variant) => {
                let evaluation = variant.evaluate(support, query, seed)?;
                outcome_of(evaluation, &support.formulation)
            }
            VariantKind::Select { candidates } => {
                let candidates = trial.earlier(&self.name, candidates, "candidate")?;
                select(trial.names(), trial.done(), &candidates)
            }
            VariantKind::LearnedBasis(variant) => {
                let model = trial.model(seed)?;
                let evaluation = variant.evaluate(model, support, query, seed)?;
                outcome_of(evaluation, &support.formulation)
            }
            VariantKind::Learn => {
                let model = trial.model(seed)?;
                let [on_support, on_query] = adapted_predictions(model, support, query);
                Outcome::unfitted(on_support, on_query, support, query)
            }
            VariantKind::LearnEnsemble { members } => {
                let seeds = ensemble_member_seeds(seed, *members).ok_or_else(|| {
                    EvaluationError::Mismatch {
                        what: format!("seed {seed}"),
                        message: "its ensemble member seeds overflow".to_string(),
                    }
                })?;
                let predictions = seeds
                    .into_iter()
                    .map(|member| Ok(adapted_predictions(trial.model(member)?, support, query)))
                    .collect::<Result<Vec<_>>>()?;
                ensemble_mean(predictions, support, query)
            }
            VariantKind::Average { members } => {
                let members: Vec<&SegmentPredictions> = trial
                    .earlier(&self.name, members, "member")?
                    .into_iter()
                    .map(|index| &trial.done()[index].predictions)
                    .collect();
                average(&members, support, query)
            }
        })
    }
}

/// `model` adapted online on `support` (its own adaptation settings), predicting both segments.
fn adapted_predictions(
    model: &MetaTrainedModel,
    support: &Segment,
    query: &Segment,
) -> [Mat<f64>; 2] {
    let adapted = model.adapt(support, &model.config.adaptation);
    [support, query].map(|segment| {
        learn::from_row_major(
            &model.predict_segment(&adapted, segment),
            model.architecture.state_dim,
        )
    })
}

/// A fitted regression's outcome: the penalty chosen per output, the mean best support score.
fn outcome_of(evaluation: VariantEvaluation, formulation: &Formulation) -> Outcome {
    let mut chosen = BTreeMap::new();
    let selections = &evaluation.fit.selections;
    for (selection, output) in selections.iter().zip(formulation.target_names()) {
        chosen.insert(output, report::Choice::Penalty(selection.chosen));
    }
    let support_cv = selections
        .iter()
        .map(|s| s.scores.iter().copied().fold(f64::INFINITY, f64::min))
        .sum::<f64>()
        / selections.len().max(1) as f64;
    Outcome {
        predictions: evaluation.predictions,
        fitted: Fitted::Regression {
            features: evaluation.feature_names,
            fit: evaluation.fit,
        },
        chosen,
        support_cv: Some(support_cv),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flights::Protocol;
    use crate::variants::testing::{RIDGE, cell, config, evaluate, segment, write};
    use learn::{CHECKPOINT_FORMAT, Standardiser};

    fn untrained_model() -> MetaTrainedModel {
        let mut config: learn::LearnConfig =
            serde_json::from_str(include_str!("../../../../experiments/learn.json")).unwrap();
        config.hidden_layers = vec![5, 4];
        config.adaptation.passes = 2;
        let architecture = learn::architecture(Formulation::Attitude, &config);
        MetaTrainedModel {
            format: CHECKPOINT_FORMAT.to_string(),
            trained_on: learn::TrainedOn::Flights(learn::FlightTraining {
                formulation: Formulation::Attitude,
                protocol: Protocol::LeaveConditionOut.name().to_string(),
                held_out_condition: None,
            }),
            seed: 2,
            parameters: architecture.initial_parameters(2),
            standardiser: Standardiser::identity(architecture.input_dim),
            architecture,
            config,
            data_files: Vec::new(),
            meta_loss_history: Vec::new(),
        }
    }

    #[test]
    fn learn_is_the_adapted_network_and_average_the_mean_of_its_members() {
        let text = config(
            &format!(
                r#"{{"name": "a", "description": "", {RIDGE}}},
                   {{"name": "l", "description": "", "kind": "learn"}},
                   {{"name": "m", "description": "", "kind": "average", "members": ["l", "a"]}}"#
            ),
            "",
        );
        let read = VariantsConfig::read(&write("evaluate", &text)).unwrap();
        let cell = cell(segment(60, 0.0), segment(40, 1.3));
        let (support, query) = (&cell.support, &cell.query);
        let model = untrained_model();
        let outcomes = evaluate(&read.variants, &|_, _| Ok(model.clone()), &cell, 1).unwrap();
        let adapted = model.adapt(support, &model.config.adaptation);
        assert_ne!(adapted, model.parameters, "adaptation moved nothing");
        let expected = model.predict_segment(&adapted, query);
        let learn = &outcomes[1].predictions;
        for i in 0..query.len() {
            for j in 0..3 {
                assert_eq!(learn.query_prediction[(i, j)], expected[i * 3 + j]);
                let mean = 0.5
                    * (learn.query_prediction[(i, j)]
                        + outcomes[0].predictions.query_prediction[(i, j)]);
                assert_eq!(outcomes[2].predictions.query_prediction[(i, j)], mean);
            }
        }
        let error = |prediction: &Mat<f64>, segment: &Segment| {
            sindy::mean_squared_error(prediction.as_ref(), segment.targets.as_ref())
        };
        assert_eq!(learn.generalisation, error(&learn.query_prediction, query));
        let average = &outcomes[2].predictions;
        assert_eq!(
            average.adaptation,
            error(&average.support_prediction, support)
        );
        assert!(outcomes[1].support_cv.is_none() && outcomes[2].chosen.is_empty());
        assert!(outcomes[0].support_cv.is_some() && outcomes[2].regression().is_none());
        assert!(outcomes[0].regression().is_some());
    }

    #[test]
    fn learn_ensemble_is_the_mean_of_its_members_each_meta_trained_once_from_its_own_seed() {
        let text = config(
            r#"{"name": "l", "description": "", "kind": "learn"},
               {"name": "a", "description": "", "kind": "learn_ensemble", "members": 3}"#,
            "",
        );
        let read = VariantsConfig::read(&write("ensemble", &text)).unwrap();
        let cell = cell(segment(60, 0.0), segment(40, 1.3));
        let (support, query) = (&cell.support, &cell.query);
        // A different (untrained) model per seed; the seeds asked for are recorded.
        let asked = std::sync::Mutex::new(Vec::new());
        let model_for = |seed: u64| {
            let mut model = untrained_model();
            model.seed = seed;
            model.parameters = model.architecture.initial_parameters(seed);
            model
        };
        let train = |_: &EvaluationCell, seed: u64| {
            asked.lock().unwrap().push(seed);
            Ok(model_for(seed))
        };
        let outcomes = evaluate(&read.variants, &train, &cell, 7).unwrap();
        // The `learn` model (seed 7) is the ensemble's first member, trained once.
        assert_eq!(*asked.lock().unwrap(), vec![7, 1_000_007, 2_000_007]);
        assert_eq!(
            ensemble_member_seeds(7, 3),
            Some(vec![7, 1_000_007, 2_000_007])
        );
        let members: Vec<[Mat<f64>; 2]> = [7, 1_000_007, 2_000_007]
            .into_iter()
            .map(|seed| adapted_predictions(&model_for(seed), support, query))
            .collect();
        let ensemble = &outcomes[1].predictions;
        for i in 0..query.len() {
            for j in 0..3 {
                let mean = members.iter().map(|m| m[1][(i, j)]).sum::<f64>() / 3.0;
                assert!(
                    (ensemble.query_prediction[(i, j)] - mean).abs() <= 1e-12 * mean.abs().max(1.0)
                );
            }
        }
        assert_eq!(outcomes[0].predictions.query_prediction, members[0][1]);
        assert_ne!(
            members[0][1], members[1][1],
            "the members are different models"
        );
        assert!(outcomes[1].chosen.is_empty() && outcomes[1].support_cv.is_none());
    }

    #[test]
    fn an_error_while_evaluating_names_the_variant() {
        // Bagging blocks longer than the support segment: found against the segment.
        let text = config(
            r#"{"name": "a", "description": "", "kind": "library", "library": {"linear": true},
               "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 3, "block": 500}}}"#,
            "",
        );
        let read = VariantsConfig::read(&write("evaluate-error", &text)).unwrap();
        let cell = cell(segment(60, 0.0), segment(40, 1.3));
        let message = evaluate(&read.variants, &|_, _| Ok(untrained_model()), &cell, 1)
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("variant 'a': ") && message.contains("bagging.block"),
            "{message}"
        );
    }
}
