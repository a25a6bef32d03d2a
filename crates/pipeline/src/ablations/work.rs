//! The ablations' work: the cells cut from the evaluation flights, the (formulation, condition,
//! seed) items enumerated, and one item run (every variant on its cell with its seed).

use std::path::Path;

use crate::experiment::{Cells, Experiment, WorkItem};
use crate::flights::read_evaluation_flights;
use crate::segment::Segment;
use crate::sindy_variant::SegmentPredictions;
use data::{Condition, FlightLog, forward_difference_noise_floor};
use learn::{Formulation, MetaTrainedModel};
use report::{MethodTrace, PublishedTables, QualitativeFigure, SeedCell};
use sindy::{EnsemblePrediction, Mat, RegressionFit};

use super::{AblationCell, AblationCellDetail, AblationSeedOutcome, AblationsContext};
use crate::cells::cell_figure;
use crate::error::{PipelineError, Result};
use crate::progress::Progress;
use crate::segment::flight_segments;
use crate::shard::{ItemResult, ShardSpec, Sweep, SweepKind};
use crate::tables::ConditionName;
use crate::variants::{CheckedVariants, Outcome, evaluate_variants, learned_basis_experiment};

/// One formulation on one evaluation flight.
struct CellData {
    formulation: Formulation,
    condition: Condition,
    support: Segment,
    query: Segment,
}

/// The ablations' work, planned: the cells cut, the LeARN flights loaded (when a variant needs
/// them) and the sweep of (formulation, condition, seed) items.
pub(super) struct AblationsWork<'c> {
    config: &'c CheckedVariants,
    cells: Vec<CellData>,
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
        let (logs, evaluation_files): (Vec<FlightLog>, Vec<learn::DataFile>) = flights
            .iter()
            .map(|flight| (flight.log.clone(), flight.file.clone()))
            .unzip();
        let cells = cut_cells(config, &conditions, &logs)?;
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
                .map(|(_, path)| data::file_sha256(path).map_err(PipelineError::from))
                .collect::<Result<_>>()?,
        };
        let items = ablation_items(&cells, &config.raw.seeds);
        Ok(Self {
            config,
            cells,
            experiment,
            dt: logs.first().map_or(0.02, |l| l.sample_interval()),
            sweep: Sweep {
                kind: SweepKind::Ablations,
                context,
                items,
                data_files,
            },
        })
    }

    /// Runs the items of `shard`, telling `progress` of each one as it ends.
    pub(super) fn run_items(
        &self,
        shard: ShardSpec,
        progress: &dyn Progress,
    ) -> Result<Vec<ItemResult<AblationSeedOutcome>>> {
        self.sweep.run(shard, |item| {
            let outcome = self.run_item(item)?;
            progress.advance(format_args!("{item}"));
            Ok(outcome)
        })
    }

    /// Every variant on the item's cell with its seed; with the first seed the cell's detail.
    fn run_item(&self, item: &WorkItem) -> Result<AblationSeedOutcome> {
        let cell = self
            .cells
            .iter()
            .find(|c| {
                c.formulation == item.formulation
                    && item.cells == Cells::Condition(c.condition.name.clone())
            })
            .ok_or_else(|| PipelineError::Mismatch {
                what: item.to_string(),
                message: "not a cell of the ablations".to_string(),
            })?;
        let outcomes = evaluate_all(self.config, self.experiment.as_ref(), cell, item.seed)?;
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
            Some(self.cell_detail(cell, &outcomes)?)
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
    fn cell_detail(&self, cell: &CellData, outcomes: &[Outcome]) -> Result<AblationCellDetail> {
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
            .map(|index| equations(&outcomes[index].regression, cell.formulation))
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

/// Every formulation × evaluation flight, cut into segments, the variants' folds and bagging
/// blocks checked against each support segment before any fit.
fn cut_cells(
    config: &CheckedVariants,
    conditions: &[&Condition],
    logs: &[FlightLog],
) -> Result<Vec<CellData>> {
    let run = &config.run;
    let mut cells = Vec::new();
    for &formulation in &run.raw.formulations {
        for (condition, log) in conditions.iter().zip(logs) {
            let (support, query) = flight_segments(log, formulation, run.segmentation())?;
            let segment = format!(
                "the {} support segment of {}",
                formulation.name(),
                log.path.display()
            );
            config
                .raw
                .check_rows(&config.path, support.len(), &segment, false)?;
            cells.push(CellData {
                formulation,
                condition: (*condition).clone(),
                support,
                query,
            });
        }
    }
    Ok(cells)
}

/// The rows of the tables, with the paper's numbers.
fn ablation_cells(config: &CheckedVariants, cells: &[CellData]) -> Result<Vec<AblationCell>> {
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
fn ablation_items(cells: &[CellData], seeds: &[u64]) -> Vec<WorkItem> {
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

/// Every variant of the configuration on one cell with one seed, in declaration order.
fn evaluate_all(
    config: &CheckedVariants,
    experiment: Option<&Experiment>,
    cell: &CellData,
    seed: u64,
) -> Result<Vec<Outcome>> {
    let meta_train = |seed: u64| -> Result<MetaTrainedModel> {
        let experiment = experiment.expect("loaded when a variant needs the LeARN networks");
        experiment.meta_train(cell.formulation, &cell.condition.name, seed)
    };
    evaluate_variants(
        &config.raw.variants,
        meta_train,
        &cell.support,
        &cell.query,
        seed,
    )
}

/// `ẋ_i = b + Σ c·feature` per output: the terms with a non-zero coefficient, ordered by the size
/// of their standardised coefficient (their share of the prediction's spread on the support
/// segment), coefficients in the units of the raw features.
fn equations(
    regression: &Option<(Vec<String>, RegressionFit)>,
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
    cell: &CellData,
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
