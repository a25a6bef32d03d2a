//! Nested validation inside the meta-training sets (leave-condition-out only): settings chosen
//! with these scores never see the evaluation flight of the fold they are used on.

use data::Condition;
use learn::{
    AdaptationConfig, Architecture, Formulation, LearnConfig, MetaTrainingOutcome, Standardiser,
    adapt_online,
};

use super::{Experiment, check_window, standardised};
use crate::error::{EvaluationError, Result};
use crate::flights::{Protocol, evaluation_condition_of};
use crate::segment::segment_batch;

/// A model meta-trained for a nested-validation pair, with the pair's conditions.
struct NestedModel<'a> {
    first: &'a Condition,
    second: &'a Condition,
    architecture: Architecture,
    standardiser: Standardiser,
    outcome: MetaTrainingOutcome,
}

/// One evaluation flight of a nested-validation pair ([`Experiment::nested_validation_detail`]).
#[derive(Clone, Debug)]
pub struct ValidationDetail {
    /// Generalisation MSE after adaptation on the whole support segment.
    pub generalisation: f64,
    /// MSE on the support segment's tail after adaptation on the rest of it.
    pub support_tail_mse: f64,
    /// The adapted model's query predictions, row-major, samples × I.
    pub query_predictions: Vec<f64>,
    /// The query targets, row-major, samples × I.
    pub query_targets: Vec<f64>,
}

impl Experiment {
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
        let score = |condition: &Condition| -> Result<Vec<f64>> {
            let cell = self.cell(formulation, &condition.name)?;
            let (support, query) = (&cell.support, &cell.query);
            for adaptation in adaptations {
                check_window(adaptation, support, &cell.flight.log.path, origin)?;
            }
            let support_batch = standardised(&standardiser, segment_batch(support));
            let query_batch = standardised(&standardiser, segment_batch(query));
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
        let first = evaluation_condition_of(&self.conditions, pair[0])?;
        let second = evaluation_condition_of(&self.conditions, pair[1])?;
        if self.protocol != Protocol::LeaveConditionOut || first.name == second.name {
            return Err(EvaluationError::Mismatch {
                what: format!("nested validation {}/{}", pair[0], pair[1]),
                message: "needs leave-condition-out and two different conditions".to_string(),
            });
        }
        let second_files: Vec<_> = self
            .conditions
            .flight_files(&self.data_dir)
            .into_iter()
            .filter(|f| f.condition == second.name)
            .map(|f| f.path)
            .collect();
        let files: Vec<_> = self
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
            return Err(EvaluationError::Mismatch {
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
        let detail = |condition: &Condition| -> Result<ValidationDetail> {
            let cell = self.cell(formulation, &condition.name)?;
            let support = standardised(&standardiser, segment_batch(&cell.support));
            let query = standardised(&standardiser, segment_batch(&cell.query));
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
                generalisation: architecture.loss(&adapted, &query.inputs, &query.targets),
                support_tail_mse,
                query_predictions: architecture.predict(&adapted, &query.inputs),
                query_targets: query.targets,
            })
        };
        Ok([detail(first)?, detail(second)?])
    }
}
