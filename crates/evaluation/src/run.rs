//! Running the experiment: SINDy and LeARN on every formulation × evaluation condition.
//!
//! Every process of a run (the unsharded one, or each shard) loads the flights (each read and
//! hashed once, by the [`Experiment`]), takes the experiment's cells and fits SINDy on them
//! (milliseconds); the LeARN work is the sweep of [`WorkItem`]s, evaluated on the same cells, each
//! item's cells carrying what the tables need ([`LearnCellOutcome`]), rendered by
//! [`crate::tables::render`]; the variant columns are evaluated on the first seed's cells with its
//! LeARN model. SINDy, LeARN and the variants are methods ([`crate::Method`]) run by the one
//! [`Runner`], scored against the targets of one [`EvaluationCell`], built once. Progress goes to
//! the caller's observer ([`Progress`]): each stage, and each LeARN cell as it ends.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use data::file_sha256;
use learn::{EquationRule, Formulation, explain, row_major};
use report::{MethodTrace, PublishedTables, QualitativeFigure, ResultsTable};

use crate::cells::{cell_figure, stacked_columns};
use crate::config::CheckedRunConfig;
use crate::error::{EvaluationError, Result};
use crate::experiment::{CellResult, Cells, EvaluationCell, Experiment, WorkItem};
use crate::progress::{NoProgress, Progress, Stage, Stopwatch};
use crate::runner::{Method, Outcome, Runner};
use crate::shard::{
    ItemResult, MergedSweep, ShardFile, ShardProvenance, ShardSpec, Sweep, SweepKind,
};
use crate::summary::{FileRef, StageTiming, Summary};
use crate::tables::{
    CellDetail, ConditionName, LearnCellOutcome, ReproduceContext, RunInputs, SindyOutcome, render,
};
use crate::variants::VariantsConfig;

/// Everything a run produced, ready to be written.
pub struct RunOutcome {
    pub tables: Vec<ResultsTable>,
    /// File name (e.g. `full_35wind.svg`) and figure.
    pub figures: Vec<(String, QualitativeFigure)>,
    pub summary: Summary,
    pub timings: Vec<StageTiming>,
    /// See [`uncommitted_inputs`].
    pub uncommitted_inputs: Option<bool>,
}

/// A shard of a reproduce run: each work item's cells.
pub type ReproduceShard = ShardFile<ReproduceContext, Vec<LearnCellOutcome>>;

/// One formulation on one evaluation flight (the experiment's cell), with SINDy fitted.
struct Cell {
    evaluation: Arc<EvaluationCell>,
    sindy: Outcome,
}

/// The stage in which the work items run.
const ITEMS_STAGE: &str = "LeARN meta-training and adaptation, variant columns";

/// Runs SINDy and LeARN for every formulation and evaluation condition of `config`, on the
/// flights under `data_dir`. `root` is the project root (for the git commit and relative paths);
/// `progress` is told of each stage and LeARN cell.
pub fn run(
    config: &CheckedRunConfig,
    data_dir: &Path,
    root: &Path,
    progress: &dyn Progress,
) -> Result<RunOutcome> {
    let mut stopwatch = Stopwatch::new(progress);
    let work = ReproduceWork::plan(config, data_dir, root, &mut stopwatch)?;
    let results = stopwatch.time(work.items_stage(ShardSpec::WHOLE), || {
        work.run_items(ShardSpec::WHOLE, progress)
    })?;
    let outcomes: Vec<LearnCellOutcome> = results.into_iter().flat_map(|r| r.result).collect();
    let (tables, figures, summary) = stopwatch.time("tables, figures and summary", || {
        render(&work.sweep.context, &outcomes, git_commit(root))
    })?;
    Ok(RunOutcome {
        tables,
        figures,
        summary,
        timings: stopwatch.timings(),
        uncommitted_inputs: uncommitted_inputs(root),
    })
}

/// Runs shard `shard` of the run of `config` (see [`run`]): the items at its positions.
pub fn run_shard(
    config: &CheckedRunConfig,
    data_dir: &Path,
    root: &Path,
    progress: &dyn Progress,
    shard: ShardSpec,
) -> Result<ReproduceShard> {
    let mut stopwatch = Stopwatch::new(progress);
    let work = ReproduceWork::plan(config, data_dir, root, &mut stopwatch)?;
    let results = stopwatch.time(work.items_stage(shard), || work.run_items(shard, progress))?;
    let provenance = ShardProvenance::here(root, stopwatch.timings());
    work.sweep.shard_file(shard, results, provenance)
}

/// The outcome of merged reproduce shards: rendered as [`run`] renders; the timings are each
/// shard's stages and the merge's.
pub fn merged_run(
    merged: MergedSweep<ReproduceContext, Vec<LearnCellOutcome>>,
) -> Result<RunOutcome> {
    let start = Instant::now();
    let outcomes: Vec<LearnCellOutcome> = merged.results.into_iter().flatten().collect();
    let (tables, figures, summary) = render(&merged.context, &outcomes, merged.git_commit)?;
    let mut timings = shard_timings(&merged.shards);
    timings.push(StageTiming {
        stage: "merge: tables, figures and summary".to_string(),
        seconds: start.elapsed().as_secs_f64(),
    });
    let uncommitted = merged.shards.iter().map(|(_, _, p)| p.uncommitted_inputs);
    Ok(RunOutcome {
        tables,
        figures,
        summary,
        timings,
        uncommitted_inputs: uncommitted
            .reduce(|a, b| a.zip(b).map(|(a, b)| a || b))
            .flatten(),
    })
}

/// Each shard's stages, named by the shard and its host.
pub fn shard_timings(shards: &[(PathBuf, ShardSpec, ShardProvenance)]) -> Vec<StageTiming> {
    shards
        .iter()
        .flat_map(|(_, shard, provenance)| {
            let host = provenance.host.as_deref().unwrap_or("unknown host");
            provenance.stages.iter().map(move |stage| StageTiming {
                stage: format!("shard {shard} on {host}: {}", stage.stage),
                seconds: stage.seconds,
            })
        })
        .collect()
}

/// A reproduce run's work, planned: the flights loaded, the cells cut and fitted by SINDy, and
/// the sweep of LeARN work items.
struct ReproduceWork<'c> {
    config: &'c CheckedRunConfig,
    experiment: Experiment,
    cells: Vec<Cell>,
    /// The variants file whose `reproduce` columns are added, if any.
    variants: Option<VariantsConfig>,
    sweep: Sweep<ReproduceContext>,
}

impl<'c> ReproduceWork<'c> {
    /// Loads the flights and fits SINDy on every cell (the stages "load flights" and "SINDy"),
    /// checks the variant columns' folds against the segments, and enumerates the work items.
    fn plan(
        config: &'c CheckedRunConfig,
        data_dir: &Path,
        root: &Path,
        stopwatch: &mut Stopwatch,
    ) -> Result<Self> {
        let experiment = stopwatch.time("load flights", || {
            Experiment::load(
                config.learn.clone(),
                config.conditions.clone(),
                data_dir,
                config.protocol,
                config.segmentation(),
            )
        })?;
        let cells = stopwatch.time("SINDy", || sindy_cells(config, &experiment))?;
        // The extra columns' folds and bagging blocks against the segments, before LeARN runs.
        let variants = match &config.variants_path {
            Some(path) => {
                let variants = VariantsConfig::read(path)?;
                for Cell { evaluation, .. } in &cells {
                    let segment = format!(
                        "the {} support segment of {}",
                        evaluation.formulation.name(),
                        evaluation.flight.log.path.display()
                    );
                    variants.check_rows(path, evaluation.support.len(), &segment, true)?;
                }
                Some(variants)
            }
            None => None,
        };
        let items = experiment.work_items(&config.raw.formulations, &config.raw.learn.seeds);
        let sweep = Sweep {
            kind: SweepKind::Reproduce,
            context: context(config, root, &experiment)?,
            items,
            data_files: experiment.data_files(),
        };
        Ok(Self {
            config,
            experiment,
            cells,
            variants,
            sweep,
        })
    }

    /// The stage of the items of `shard`, counting their LeARN cells.
    fn items_stage(&self, shard: ShardSpec) -> Stage<'static> {
        let conditions = self.sweep.context.conditions.len();
        let cells: usize = shard
            .positions(self.sweep.items.len())
            .iter()
            .map(|&p| match self.sweep.items[p].cells {
                Cells::Condition(_) => 1,
                Cells::Every => conditions,
            })
            .sum();
        Stage::counting(ITEMS_STAGE, "LeARN", cells)
    }

    /// Runs the items of `shard`, telling `progress` of each cell as it ends.
    fn run_items(
        &self,
        shard: ShardSpec,
        progress: &dyn Progress,
    ) -> Result<Vec<ItemResult<Vec<LearnCellOutcome>>>> {
        self.sweep.run(shard, |item| self.run_item(item, progress))
    }

    /// One work item: LeARN on its cells; with the first seed, each cell's detail too.
    fn run_item(&self, item: &WorkItem, progress: &dyn Progress) -> Result<Vec<LearnCellOutcome>> {
        let results = self.experiment.run_item(item, progress)?;
        let first_seed = item.seed == self.config.raw.learn.seeds[0];
        results
            .iter()
            .map(|result| {
                let cell = self.cell(item.formulation, &result.summary.condition)?;
                let detail = if first_seed {
                    Some(self.cell_detail(cell, result)?)
                } else {
                    None
                };
                Ok(LearnCellOutcome {
                    summary: result.summary.clone(),
                    final_meta_loss: result.model.meta_loss_history.last().copied(),
                    meta_training_files: result.model.data_files.clone(),
                    first_seed: detail,
                })
            })
            .collect()
    }

    fn cell(&self, formulation: Formulation, condition: &str) -> Result<&Cell> {
        self.cells
            .iter()
            .find(|c| {
                c.evaluation.formulation == formulation && c.evaluation.condition.name == condition
            })
            .ok_or_else(|| EvaluationError::Mismatch {
                what: format!("{} {condition}", formulation.name()),
                message: "LeARN evaluated a cell the run does not have".to_string(),
            })
    }

    /// What the tables take from the first seed's cell: SINDy and the flight, the figure, the
    /// explanation of the adapted model, the variant columns with its model.
    fn cell_detail(&self, cell: &Cell, result: &CellResult) -> Result<CellDetail> {
        let (evaluation, model) = (&cell.evaluation, &result.model);
        let support_inputs = model
            .standardiser
            .apply(&row_major(&evaluation.support.inputs()));
        let explanation = explain(
            evaluation.formulation,
            &model.architecture,
            &result.adapted_parameters,
            &support_inputs,
            EquationRule::default(),
        );
        let variant_columns = match &self.variants {
            Some(variants) => crate::variants::reproduce_columns(variants, evaluation, model)?,
            None => BTreeMap::new(),
        };
        let sindy = &cell.sindy.predictions;
        let equations = cell.sindy.sindy().map(|model| model.equations(3));
        Ok(CellDetail {
            flight: evaluation.flight.file.clone(),
            support_rows: [evaluation.support.rows.start, evaluation.support.rows.end],
            query_rows: [evaluation.query.rows.start, evaluation.query.rows.end],
            sindy: SindyOutcome {
                adaptation: sindy.adaptation,
                generalisation: sindy.generalisation,
                equations: equations.ok_or_else(|| EvaluationError::Mismatch {
                    what: format!(
                        "{} {}",
                        evaluation.formulation.name(),
                        evaluation.condition.name
                    ),
                    message: "SINDy's outcome has no model".to_string(),
                })?,
                query_coverage: sindy_query_coverage(cell, result),
            },
            explanation,
            figure: figure(cell, result)?,
            variant_columns,
        })
    }
}

/// The context of a reproduce run of `config`: everything rendering takes from the configuration.
fn context(
    config: &CheckedRunConfig,
    root: &Path,
    experiment: &Experiment,
) -> Result<ReproduceContext> {
    let run_config_path = config
        .path
        .strip_prefix(root)
        .map(PathBuf::from)
        .unwrap_or_else(|_| config.path.clone());
    let input_sha256 = config
        .input_files("--config")
        .iter()
        .map(|(_, path)| file_sha256(path).map_err(EvaluationError::from))
        .collect::<Result<_>>()?;
    Ok(ReproduceContext {
        run: config.raw.name.clone(),
        description: config.raw.description.clone(),
        formulations: config.raw.formulations.clone(),
        conditions: config
            .conditions
            .evaluation()
            .map(|c| ConditionName {
                name: c.name.clone(),
                label: c.label().to_string(),
            })
            .collect(),
        published: PublishedTables::load(&config.published_path)?,
        protocol: experiment.protocol().name().to_string(),
        inputs: RunInputs {
            run_config: FileRef {
                path: run_config_path,
                sha256: config.sha256.clone(),
            },
            conditions: file_ref(&config.raw.conditions, &config.conditions_path)?,
            published: file_ref(&config.raw.published, &config.published_path)?,
            learn_config: file_ref(&config.raw.learn.config, &config.learn_config_path)?,
            learn_overrides: config.raw.learn.overrides.clone(),
            split: config.raw.split,
            derivative: config.raw.derivative,
            seeds: config.raw.learn.seeds.clone(),
            sindy: config.raw.sindy.clone(),
            learn: config.learn.get().clone(),
        },
        input_sha256,
        evaluation_files: experiment
            .evaluation_flights()
            .iter()
            .map(|f| f.file.clone())
            .collect(),
    })
}

/// SINDy on every formulation × evaluation flight of the run, in table order, on the
/// experiment's cells (by the [`Runner`]: SINDy is a method like the others; its seed plays no
/// part).
fn sindy_cells(config: &CheckedRunConfig, experiment: &Experiment) -> Result<Vec<Cell>> {
    let conditions = experiment.evaluation_conditions();
    let cells: Vec<Arc<EvaluationCell>> = config
        .raw
        .formulations
        .iter()
        .flat_map(|&f| conditions.iter().map(move |c| (f, c.as_str())))
        .map(|(formulation, condition)| experiment.cell(formulation, condition).cloned())
        .collect::<Result<_>>()?;
    let runner = Runner::new([&config.raw.sindy as &dyn Method], None);
    let outcomes = runner.run_cells(&cells, config.raw.learn.seeds[0], &NoProgress)?;
    cells
        .into_iter()
        .zip(outcomes)
        .map(|(evaluation, mut outcomes)| {
            let sindy = outcomes.pop().ok_or_else(|| EvaluationError::Mismatch {
                what: evaluation.flight.log.path.display().to_string(),
                message: "SINDy gave no outcome".to_string(),
            })?;
            Ok(Cell { evaluation, sindy })
        })
        .collect()
}

/// SINDy's query predictions scored on the same split as LeARN's query coverage: the samples
/// inside and outside the range of the LeARN meta-training inputs (SINDy itself never saw those
/// flights; the split only asks whether the samples where LeARN extrapolates are hard for SINDy
/// too). `None` without a range.
fn sindy_query_coverage(cell: &Cell, learn_result: &CellResult) -> Option<learn::RangeCoverage> {
    let query = &cell.evaluation.query;
    let names = cell.evaluation.formulation.input_names();
    learn_result.model.standardiser.coverage_with_errors(
        &row_major(&query.inputs()),
        &names,
        &row_major(&cell.sindy.predictions.query_prediction),
        &row_major(&query.targets),
    )
}

fn figure(cell: &Cell, learn_result: &CellResult) -> Result<(String, QualitativeFigure)> {
    let methods = vec![
        MethodTrace {
            method: "SINDy".to_string(),
            prediction: stacked_columns(
                &cell.sindy.predictions.support_prediction,
                &cell.sindy.predictions.query_prediction,
            ),
            band: None,
        },
        MethodTrace {
            method: "LeARN".to_string(),
            prediction: stacked_columns(
                &learn_result.support.predictions,
                &learn_result.query.predictions,
            ),
            band: None,
        },
    ];
    let evaluation = &cell.evaluation;
    cell_figure(
        evaluation.formulation,
        &evaluation.condition,
        &evaluation.support,
        &evaluation.query,
        methods,
    )
}

fn file_ref(written: &Path, resolved: &Path) -> Result<FileRef> {
    Ok(FileRef {
        path: written.to_path_buf(),
        sha256: file_sha256(resolved)?,
    })
}

/// Paths a run writes (relative to the project root); they do not count as inputs of a run.
pub const GENERATED_PATHS: [&str; 3] = ["results", "paper/tables", "README.md"];

fn git(root: &Path, arguments: &[&str]) -> Option<String> {
    let exclusions = GENERATED_PATHS.map(|p| format!(":(exclude){p}"));
    std::process::Command::new("git")
        .arg("-C")
        .arg(root)
        .args(arguments)
        .arg("--")
        .arg(".")
        .args(&exclusions)
        .output()
        .ok()
        .filter(|output| output.status.success())
        .and_then(|output| String::from_utf8(output.stdout).ok())
}

/// The threads the run's parallel work uses: rayon's pool (`RAYON_NUM_THREADS` when set, else
/// the processors available), as the banner, `timings.json` and shard provenance report it.
pub fn worker_threads() -> usize {
    rayon::current_num_threads()
}

/// The last commit that changed an input of the run (anything but [`GENERATED_PATHS`]), or
/// `unknown` outside a git checkout. Committing regenerated results on their own therefore leaves
/// this value, and so `summary.json`, unchanged.
pub fn git_commit(root: &Path) -> String {
    git(root, &["log", "-1", "--format=%H"])
        .map(|text| text.trim().to_string())
        .filter(|text| !text.is_empty())
        .unwrap_or_else(|| "unknown".to_string())
}

/// Whether tracked inputs of the run (anything but [`GENERATED_PATHS`]) differ from
/// [`git_commit`]; `None` outside a git checkout.
pub fn uncommitted_inputs(root: &Path) -> Option<bool> {
    git(root, &["status", "--porcelain", "--untracked-files=no"])
        .map(|text| !text.trim().is_empty())
}
