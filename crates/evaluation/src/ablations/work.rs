//! The ablations' work: the cells cut from the evaluation flights, the (formulation, condition,
//! seed) items enumerated, and the items run: every variant on its cell with its seed, by the
//! [`Runner`].

use std::path::Path;
use std::sync::Arc;

use crate::experiment::{Cells, EvaluationCell, Experiment, WorkItem, evaluation_cells};
use crate::flights::read_evaluation_flights;
use crate::noise_floor::forward_difference_noise_floor;
use crate::runner::{Method, Outcome, Runner, item_cells};
use crate::sindy_variant::SegmentPredictions;
use data::Condition;
use learn::{Formulation, MetaTrainedModel};
use report::{MethodTrace, PublishedTables, QualitativeFigure, SeedCell};
use sindy::{EnsemblePrediction, Mat, RegressionFit};

use super::{AblationCell, AblationCellDetail, AblationSeedOutcome, AblationsContext};
use crate::cells::cell_figure;
use crate::error::{EvaluationError, Result};
use crate::progress::Progress;
use crate::shard::{ItemResult, ShardSpec, Sweep, SweepKind};
use crate::tables::ConditionName;
use crate::variants::{CheckedVariants, learned_basis_experiment};

/// The ablations' work, planned: the cells cut, the LeARN flights loaded (when a variant needs
/// them) and the sweep of (formulation, condition, seed) items.
pub(super) struct AblationsWork<'c> {
    config: &'c CheckedVariants,
    cells: Vec<Arc<EvaluationCell>>,
    experiment: Option<Experiment>,
    /// The sample interval of the first evaluation flight (the noise floors' time step).
    dt: f64,
    pub(super) sweep: Sweep<AblationsContext>,
}

impl<'c> AblationsWork<'c> {
    /// Loads the evaluation flights, cuts every cell and checks the variants' folds against its
    /// support segment, loads the LeARN flights when a variant needs them, enumerates the items.
    pub(super) fn plan(config: &'c CheckedVariants, data_dir: &Path) -> Result<Self> {
        let run = &config.run;
        let conditions: Vec<&Condition> = run.conditions.evaluation().collect();
        let flights = read_evaluation_flights(&run.conditions, data_dir)?;
        let evaluation_files: Vec<learn::DataFile> =
            flights.iter().map(|flight| flight.file.clone()).collect();
        let cells = cut_cells(config, &conditions, &flights)?;
        let needs_learn = config
            .raw
            .variants
            .iter()
            .any(|v| v.kind.needs_meta_training());
        let experiment = if needs_learn {
            Some(learned_basis_experiment(config, data_dir, &flights)?)
        } else {
            None
        };
        let mut data_files = evaluation_files.clone();
        data_files.extend(experiment.iter().flat_map(Experiment::data_files));
        data_files.sort_by(|a, b| a.path.cmp(&b.path));
        data_files.dedup_by(|a, b| a.path == b.path);
        let context = AblationsContext {
            config: config.raw.clone(),
            segmentation: run.segmentation(),
            cells: ablation_cells(config, &cells)?,
            evaluation_files,
            learn_config: experiment.as_ref().map(|e| e.config().get().clone()),
            input_sha256: config
                .input_files("--config")
                .iter()
                .map(|(_, path)| data::file_sha256(path).map_err(EvaluationError::from))
                .collect::<Result<_>>()?,
        };
        let items = ablation_items(&cells, &config.raw.seeds);
        Ok(Self {
            config,
            cells,
            experiment,
            dt: flights.first().map_or(0.02, |f| f.log.sample_interval()),
            sweep: Sweep {
                kind: SweepKind::Ablations,
                context,
                items,
                data_files,
            },
        })
    }

    /// Runs the items of `shard` (every variant on the item's cell with its seed), telling
    /// `progress` of each one as it ends.
    pub(super) fn run_items(
        &self,
        shard: ShardSpec,
        progress: &dyn Progress,
    ) -> Result<Vec<ItemResult<AblationSeedOutcome>>> {
        // The networks of the cell's fold, from the run's experiment with the variants file's
        // `learn_overrides` (loaded when a variant asks for them).
        let train = |cell: &EvaluationCell, seed: u64| -> Result<MetaTrainedModel> {
            match &self.experiment {
                Some(experiment) => {
                    experiment.meta_train(cell.formulation, &cell.condition.name, seed)
                }
                None => Err(EvaluationError::Mismatch {
                    what: format!("{} {}", cell.formulation.name(), cell.condition.name),
                    message: "no variant was expected to need the LeARN networks".to_string(),
                }),
            }
        };
        let variants = self.config.raw.variants.iter().map(|v| v as &dyn Method);
        let runner = Runner::new(variants, Some(&train));
        self.sweep.run(shard, |item| {
            let cells = item_cells(&self.cells, item)?;
            let outcomes = runner.run_cells(&cells, item.seed, progress)?;
            match (cells.as_slice(), outcomes.as_slice()) {
                ([cell], [outcomes]) => self.item_outcome(item, cell, outcomes),
                _ => Err(EvaluationError::Mismatch {
                    what: item.to_string(),
                    message: "an ablation item is one cell".to_string(),
                }),
            }
        })
    }

    /// The item's result from every variant's outcome on its cell; with the first seed the
    /// cell's detail.
    fn item_outcome(
        &self,
        item: &WorkItem,
        cell: &EvaluationCell,
        outcomes: &[Outcome],
    ) -> Result<AblationSeedOutcome> {
        let variants = outcomes
            .iter()
            .map(|outcome| SeedCell {
                seed: item.seed,
                adaptation: outcome.predictions.adaptation,
                generalisation: outcome.predictions.generalisation,
                support_cv: outcome.support_cv,
                chosen: outcome.chosen.clone(),
                query_band_coverage: outcome
                    .predictions
                    .query_band
                    .as_ref()
                    .map(|band| coverage(band, &cell.query.targets)),
            })
            .collect();
        let first_seed = if item.seed == self.config.raw.seeds[0] {
            Some(self.cell_detail(cell, outcomes)?)
        } else {
            None
        };
        Ok(AblationSeedOutcome {
            variants,
            first_seed,
        })
    }

    /// SINDy and the noise floors of `cell`, and from the first seed's `outcomes` the headline
    /// equations and the figure.
    fn cell_detail(
        &self,
        cell: &EvaluationCell,
        outcomes: &[Outcome],
    ) -> Result<AblationCellDetail> {
        let raw = &self.config.raw;
        let position = |name: &str| raw.variants.iter().position(|v| v.name == name);
        let sindy = crate::sindy_column::fit_and_evaluate(
            &self.config.run.raw.sindy,
            &cell.support,
            &cell.query,
        )?;
        let headline_equations = raw
            .equations_variant(&raw.headline)
            .and_then(position)
            .map(|index| equations(outcomes[index].regression(), cell.formulation))
            .unwrap_or_default();
        let figure = match raw.figure_variant.as_deref() {
            Some(name) => match position(name) {
                Some(index) => Some(figure(cell, name, &outcomes[index].predictions)?),
                None => None,
            },
            None => None,
        };
        Ok(AblationCellDetail {
            sindy: report::Mse {
                adaptation: sindy.adaptation,
                generalisation: sindy.generalisation,
            },
            noise_floor_support: forward_difference_noise_floor(
                cell.support.states.as_ref(),
                self.dt,
            )?,
            noise_floor_query: forward_difference_noise_floor(cell.query.states.as_ref(), self.dt)?,
            headline_equations,
            figure,
        })
    }
}

/// Every formulation of the run × evaluation flight, cut by the run's segmentation, the variants'
/// folds and bagging blocks checked against each support segment before any fit.
fn cut_cells(
    config: &CheckedVariants,
    conditions: &[&Condition],
    flights: &[Arc<crate::flights::Flight>],
) -> Result<Vec<Arc<EvaluationCell>>> {
    let run = &config.run;
    let cells = evaluation_cells(
        &run.raw.formulations,
        conditions,
        flights,
        run.segmentation(),
    )?;
    for cell in &cells {
        let segment = format!(
            "the {} support segment of {}",
            cell.formulation.name(),
            cell.flight.log.path.display()
        );
        config
            .raw
            .check_rows(&config.path, cell.support.len(), &segment, false)?;
    }
    Ok(cells)
}

/// The rows of the tables, with the paper's numbers.
fn ablation_cells(
    config: &CheckedVariants,
    cells: &[Arc<EvaluationCell>],
) -> Result<Vec<AblationCell>> {
    let published = PublishedTables::load(&config.run.published_path)?;
    Ok(cells
        .iter()
        .map(|cell| AblationCell {
            formulation: cell.formulation,
            condition: ConditionName {
                name: cell.condition.name.clone(),
                label: cell.condition.label().to_string(),
            },
            published: published
                .get(cell.formulation.name(), cell.condition.label())
                .copied(),
        })
        .collect())
}

/// The ablations' work: every cell (in row order) × every seed (in the configuration's order).
fn ablation_items(cells: &[Arc<EvaluationCell>], seeds: &[u64]) -> Vec<WorkItem> {
    cells
        .iter()
        .flat_map(|cell| {
            seeds.iter().map(|&seed| WorkItem {
                formulation: cell.formulation,
                cells: Cells::Condition(cell.condition.name.clone()),
                seed,
            })
        })
        .collect()
}

/// `ẋ_i = b + Σ c·feature` per output: the terms with a non-zero coefficient, ordered by the size
/// of their standardised coefficient (their share of the prediction's spread on the support
/// segment), coefficients in the units of the raw features.
fn equations(
    regression: Option<(&[String], &RegressionFit)>,
    formulation: Formulation,
) -> Vec<String> {
    let Some((feature_names, fit)) = regression else {
        return Vec::new();
    };
    let fit = &fit.full;
    let (raw, intercepts) = fit.raw_coefficients();
    formulation
        .target_names()
        .iter()
        .enumerate()
        .map(|(j, output)| {
            let mut terms: Vec<usize> = (0..raw.nrows())
                .filter(|&i| fit.coefficients[(i, j)] != 0.0)
                .collect();
            terms.sort_by(|&a, &b| {
                fit.coefficients[(b, j)]
                    .abs()
                    .total_cmp(&fit.coefficients[(a, j)].abs())
            });
            let mut text = format!("{output} = {:.4}", intercepts[j]);
            for i in terms {
                let c = raw[(i, j)];
                let sign = if c < 0.0 { '-' } else { '+' };
                text.push_str(&format!(" {sign} {:.4} {}", c.abs(), feature_names[i]));
            }
            text
        })
        .collect()
}

/// The fraction of `targets` inside the band.
fn coverage(band: &EnsemblePrediction, targets: &Mat<f64>) -> f64 {
    let (n, m) = targets.shape();
    let inside = (0..m)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .filter(|&(i, j)| {
            band.lower[(i, j)] <= targets[(i, j)] && targets[(i, j)] <= band.upper[(i, j)]
        })
        .count();
    inside as f64 / (n * m) as f64
}

fn band_series(support: &EnsemblePrediction, query: &EnsemblePrediction) -> report::Band {
    report::Band {
        lower: crate::cells::stacked_columns(&support.lower, &query.lower),
        upper: crate::cells::stacked_columns(&support.upper, &query.upper),
    }
}

fn figure(
    cell: &EvaluationCell,
    name: &str,
    predictions: &SegmentPredictions,
) -> Result<(String, QualitativeFigure)> {
    let band = match (&predictions.support_band, &predictions.query_band) {
        (Some(s), Some(q)) => Some(band_series(s, q)),
        _ => None,
    };
    let method = MethodTrace {
        method: name.to_string(),
        prediction: crate::cells::stacked_columns(
            &predictions.support_prediction,
            &predictions.query_prediction,
        ),
        band,
    };
    cell_figure(
        cell.formulation,
        &cell.condition,
        &cell.support,
        &cell.query,
        vec![method],
    )
}
