//! Running the experiment: SINDy and LeARN on every formulation × evaluation condition.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::sindy_column::SegmentEvaluation;
use data::{Condition, FlightLog, Formulation, Mat, Segment, SplitSpec, file_sha256};
use indicatif::{ProgressBar, ProgressStyle};
use learn::{CellResult, DataFile, EquationRule, Experiment, RangeCoverage, explain, row_major};
use rayon::prelude::*;
use report::{MethodTrace, Mse, OutputAxis, PublishedTables, QualitativeFigure, ResultsTable, Row};
use sindy::Derivative;

use crate::config::CheckedRunConfig;
use crate::error::{PipelineError, Result, in_flight};
use crate::summary::{
    CellRecord, FileRef, InputContribution, LearnCell, LearnSeedCell, Provenance, SUMMARY_FORMAT,
    SindyCell, StageTiming, Summary,
};

/// How a run reports progress.
pub struct RunOptions<'a> {
    /// Draw progress bars (the caller decides: not quiet and a terminal).
    pub show_progress: bool,
    /// Called when a stage finishes, with its wall time.
    pub on_stage: &'a (dyn Fn(&StageTiming) + Sync),
}

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

/// One formulation on one evaluation flight.
struct Cell<'a> {
    formulation: Formulation,
    condition: &'a Condition,
    flight: &'a EvaluationFlight,
    support: Segment,
    query: Segment,
    sindy: SegmentEvaluation,
}

struct EvaluationFlight {
    log: FlightLog,
    file: DataFile,
}

/// Times stages and reports each one as it ends.
struct Stopwatch<'a> {
    options: &'a RunOptions<'a>,
    timings: Vec<StageTiming>,
}

impl Stopwatch<'_> {
    fn time<T>(&mut self, stage: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
        let start = Instant::now();
        let value = work()?;
        let timing = StageTiming {
            stage: stage.to_string(),
            seconds: start.elapsed().as_secs_f64(),
        };
        (self.options.on_stage)(&timing);
        self.timings.push(timing);
        Ok(value)
    }
}

fn progress_bar(show: bool, length: usize, message: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(length as u64).with_message(message.to_string());
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:32}] {pos}/{len} cells, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// Runs SINDy and LeARN for every formulation and evaluation condition of `config`, on the
/// flights under `data_dir`. `root` is the project root (for the git commit and relative paths).
pub fn run(
    config: &CheckedRunConfig,
    data_dir: &Path,
    root: &Path,
    options: &RunOptions,
) -> Result<RunOutcome> {
    let mut stopwatch = Stopwatch {
        options,
        timings: Vec::new(),
    };
    let conditions: Vec<&Condition> = config.conditions.evaluation().collect();
    let (experiment, flights) = stopwatch.time("load flights", || {
        let experiment = Experiment::load(
            config.learn.clone(),
            config.conditions.clone(),
            data_dir,
            config.protocol,
        )?;
        let flights = conditions
            .par_iter()
            .map(|condition| load_evaluation_flight(config, data_dir, condition))
            .collect::<Result<Vec<_>>>()?;
        Ok((experiment, flights))
    })?;

    let jobs: Vec<(Formulation, usize)> = config
        .raw
        .formulations
        .iter()
        .flat_map(|&f| (0..conditions.len()).map(move |c| (f, c)))
        .collect();
    let cells = stopwatch.time("SINDy", || {
        let bar = progress_bar(options.show_progress, jobs.len(), "SINDy");
        let cells = jobs
            .par_iter()
            .map(|&(formulation, index)| {
                let cell = sindy_cell(config, formulation, conditions[index], &flights[index]);
                bar.inc(1);
                cell
            })
            .collect::<Result<Vec<_>>>();
        bar.finish_and_clear();
        cells
    })?;

    // The extra columns' folds and bagging blocks against the segments, before LeARN runs.
    if let Some(path) = &config.raw.variants {
        let path = root.join(path);
        let variants = crate::variants::VariantsConfig::read(&path)?;
        for cell in &cells {
            let segment = format!(
                "the {} support segment of {}",
                cell.formulation.name(),
                cell.flight.log.path.display()
            );
            variants.check_rows(&path, cell.support.len(), &segment, true)?;
        }
    }

    let seeds = &config.raw.learn.seeds;
    let learn_results = stopwatch.time("LeARN meta-training and adaptation", || {
        let bar = progress_bar(options.show_progress, jobs.len() * seeds.len(), "LeARN");
        let mut per_seed = Vec::with_capacity(seeds.len());
        for &seed in seeds {
            per_seed.push(learn_cells(&experiment, &cells, seed, &bar)?);
        }
        bar.finish_and_clear();
        Ok(per_seed)
    })?;

    let variant_columns = match &config.raw.variants {
        Some(path) => stopwatch.time("variants", || {
            // The run's own LeARN models (first seed) serve the variants that need them.
            let cells: Vec<_> = cells
                .iter()
                .zip(&learn_results[0])
                .map(|(c, learn)| (&c.support, &c.query, &learn.model))
                .collect();
            crate::variants::reproduce_columns(&root.join(path), &cells)
        })?,
        None => Vec::new(),
    };

    let (tables, figures, summary) = stopwatch.time("tables, figures and summary", || {
        let published = PublishedTables::load(&config.published_path)?;
        let protocol = experiment.protocol().name().to_string();
        let mut tables = build_tables(config, &cells, &learn_results, &published, &protocol);
        for (cell, columns) in cells.iter().zip(&variant_columns) {
            let table = tables
                .iter_mut()
                .find(|t| t.table == cell.formulation.name());
            let row = table.and_then(|t| {
                t.rows
                    .iter_mut()
                    .find(|r| r.condition == cell.condition.label())
            });
            if let Some(row) = row {
                row.variants.extend(columns.clone());
            }
        }
        let figures = cells
            .iter()
            .enumerate()
            .map(|(index, cell)| figure(cell, &learn_results[0][index]))
            .collect::<Result<Vec<_>>>()?;
        let records = cells
            .iter()
            .enumerate()
            .map(|(index, cell)| record(cell, &learn_results, index))
            .collect::<Result<Vec<_>>>()?;
        let provenance = provenance(config, root, &flights, &learn_results, protocol)?;
        let summary = Summary {
            format: SUMMARY_FORMAT.to_string(),
            run: config.raw.name.clone(),
            description: config.raw.description.clone(),
            provenance,
            tables: tables.clone(),
            cells: records,
        };
        Ok((tables, figures, summary))
    })?;

    Ok(RunOutcome {
        tables,
        figures,
        summary,
        timings: stopwatch.timings,
        uncommitted_inputs: uncommitted_inputs(root),
    })
}

fn load_evaluation_flight(
    config: &CheckedRunConfig,
    data_dir: &Path,
    condition: &Condition,
) -> Result<EvaluationFlight> {
    let path = config.conditions.flight_path(
        data_dir,
        condition,
        &config.conditions.evaluation_controller,
    );
    let log = FlightLog::read(&path)?;
    let file = DataFile {
        path: path.strip_prefix(data_dir).unwrap_or(&path).to_path_buf(),
        sha256: file_sha256(&path)?,
    };
    Ok(EvaluationFlight { log, file })
}

fn sindy_cell<'a>(
    config: &CheckedRunConfig,
    formulation: Formulation,
    condition: &'a Condition,
    flight: &'a EvaluationFlight,
) -> Result<Cell<'a>> {
    let (support, query) = flight_segments(
        &flight.log,
        formulation,
        config.raw.split,
        config.raw.derivative,
    )?;
    let sindy = crate::sindy_column::fit_and_evaluate(&config.raw.sindy, &support, &query)
        .map_err(|error| in_flight(&flight.log.path, error))?;
    Ok(Cell {
        formulation,
        condition,
        flight,
        support,
        query,
        sindy,
    })
}

/// The support and query segments of `log` (cut by `split`, targets by `derivative` on each
/// segment); errors name the flight's file.
pub(crate) fn flight_segments(
    log: &FlightLog,
    formulation: Formulation,
    split: SplitSpec,
    derivative: Derivative,
) -> Result<(Segment, Segment)> {
    let segments = || -> std::result::Result<(Segment, Segment), data::DataError> {
        let rows = split.split(log.len())?;
        let support = formulation.segment(log, rows.support, derivative)?;
        let query = formulation.segment(log, rows.query, derivative)?;
        Ok((support, query))
    };
    segments().map_err(|error| in_flight(&log.path, error))
}

/// LeARN for every cell with one seed, in the cells' order. Under the `paper` protocol one
/// meta-trained model per formulation serves every condition.
fn learn_cells(
    experiment: &Experiment,
    cells: &[Cell],
    seed: u64,
    bar: &ProgressBar,
) -> Result<Vec<CellResult>> {
    let shared_models = if experiment.protocol() == learn::Protocol::Paper {
        let mut formulations: Vec<Formulation> = cells.iter().map(|c| c.formulation).collect();
        formulations.dedup();
        let first_condition = &cells[0].condition.name;
        formulations
            .par_iter()
            .map(|&f| Ok((f, experiment.meta_train(f, first_condition, seed)?)))
            .collect::<Result<Vec<_>>>()?
    } else {
        Vec::new()
    };
    cells
        .par_iter()
        .map(|cell| {
            let result = match shared_models.iter().find(|(f, _)| *f == cell.formulation) {
                Some((_, model)) => experiment.evaluate(model, &cell.condition.name)?,
                None => experiment.run_cell(cell.formulation, &cell.condition.name, seed)?,
            };
            check_same_targets(cell, &result)?;
            bar.inc(1);
            Ok(result)
        })
        .collect()
}

/// Both methods must be scored against the same targets on the same rows.
fn check_same_targets(cell: &Cell, result: &CellResult) -> Result<()> {
    let pairs = [
        (&cell.support.targets, &result.support.targets, "support"),
        (&cell.query.targets, &result.query.targets, "query"),
    ];
    for (ours, theirs, segment) in pairs {
        let same_shape = ours.nrows() == theirs.nrows() && ours.ncols() == theirs.ncols();
        let largest = if same_shape {
            max_abs_difference(ours, theirs)
        } else {
            f64::INFINITY
        };
        if largest > 1e-12 {
            return Err(PipelineError::Mismatch {
                what: format!(
                    "{} {} {segment} segment",
                    cell.formulation.name(),
                    cell.condition.label()
                ),
                message: format!("SINDy and LeARN targets differ (largest difference {largest:e})"),
            });
        }
    }
    Ok(())
}

fn max_abs_difference(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    let mut largest = 0.0f64;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            largest = largest.max((a[(i, j)] - b[(i, j)]).abs());
        }
    }
    largest
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / count as f64
}

/// The LeARN errors of cell `index`, averaged over seeds.
fn learn_mse(learn_results: &[Vec<CellResult>], index: usize) -> Mse {
    Mse {
        adaptation: mean(learn_results.iter().map(|r| r[index].summary.adapt_mse)),
        generalisation: mean(learn_results.iter().map(|r| r[index].summary.gen_mse)),
    }
}

fn build_tables(
    config: &CheckedRunConfig,
    cells: &[Cell],
    learn_results: &[Vec<CellResult>],
    published: &PublishedTables,
    protocol: &str,
) -> Vec<ResultsTable> {
    config
        .raw
        .formulations
        .iter()
        .map(|formulation| {
            let indices: Vec<usize> = (0..cells.len())
                .filter(|&index| cells[index].formulation == *formulation)
                .collect();
            let rows = indices
                .iter()
                .map(|&index| {
                    let cell = &cells[index];
                    Row::new(
                        cell.condition.label(),
                        Mse {
                            adaptation: cell.sindy.support_mse,
                            generalisation: cell.sindy.query_mse,
                        },
                        learn_mse(learn_results, index),
                    )
                })
                .collect();
            let learn_coverages: Vec<Option<RangeCoverage>> = indices
                .iter()
                .map(|&index| seed_mean_coverage(learn_results, index, |s| &s.query_coverage))
                .collect();
            let coverages = indices.iter().zip(&learn_coverages).map(|(&index, learn)| {
                (
                    cells[index].condition.label(),
                    learn.as_ref(),
                    sindy_query_coverage(&cells[index], &learn_results[0][index]),
                )
            });
            let mut table = ResultsTable {
                table: formulation.name().to_string(),
                protocol: protocol.to_string(),
                rows,
                notes: coverage_note(coverages).into_iter().collect(),
            };
            table.attach_published(published);
            table
        })
        .collect()
}

/// A cell's coverage (`field` of each seed's summary) with LeARN's errors averaged over the seeds,
/// as its MSE is; the first seed's if the seeds' counts disagree.
fn seed_mean_coverage(
    learn_results: &[Vec<CellResult>],
    index: usize,
    field: fn(&learn::CellSummary) -> &Option<RangeCoverage>,
) -> Option<RangeCoverage> {
    let per_seed: Option<Vec<&RangeCoverage>> = learn_results
        .iter()
        .map(|results| field(&results[index].summary).as_ref())
        .collect();
    let per_seed = per_seed?;
    RangeCoverage::mean(&per_seed).or_else(|| per_seed.first().map(|c| (*c).clone()))
}

/// SINDy's query predictions scored on the same split as LeARN's query coverage: the samples
/// inside and outside the range of the LeARN meta-training inputs (SINDy itself never saw those
/// flights; the split only asks whether the samples where LeARN extrapolates are hard for SINDy
/// too). `None` without a range.
fn sindy_query_coverage(cell: &Cell, learn_result: &CellResult) -> Option<RangeCoverage> {
    let names = cell.formulation.input_names();
    learn_result.model.standardiser.coverage_with_errors(
        &row_major(&cell.query.inputs()),
        &names,
        &row_major(&cell.sindy.query_prediction),
        &row_major(&cell.query.targets),
    )
}

/// The note under a table on how much of each query segment lies outside the range of the
/// meta-training inputs (where the networks extrapolate), naming the input that goes farthest,
/// with LeARN's and SINDy's generalisation MSE over the samples inside and outside that range;
/// `None` if no cell has a range.
fn coverage_note<'a>(
    coverages: impl Iterator<Item = (&'a str, Option<&'a RangeCoverage>, Option<RangeCoverage>)>,
) -> Option<String> {
    let split = |coverage: Option<&RangeCoverage>| match coverage {
        Some(RangeCoverage {
            mse_inside: Some(inside),
            mse_outside: Some(outside),
            ..
        }) => Some(format!("{inside:.3} / {outside:.3}")),
        _ => None,
    };
    let parts: Vec<String> = coverages
        .filter_map(|(label, coverage, sindy)| {
            let coverage = coverage?;
            let farthest = coverage
                .inputs
                .iter()
                .filter(|input| input.samples_outside > 0)
                .max_by(|a, b| a.largest_excess_in_std.total_cmp(&b.largest_excess_in_std));
            let errors = match (split(Some(coverage)), split(sindy.as_ref())) {
                (Some(learn), Some(sindy)) => {
                    format!("; MSE inside / outside: LeARN {learn}, SINDy {sindy}")
                }
                (Some(learn), None) => format!("; MSE inside / outside: LeARN {learn}"),
                _ => String::new(),
            };
            let detail = farthest.map_or(String::new(), |input| {
                format!(
                    " (farthest: {} by {:.1} std on {} samples{}{errors})",
                    input.input,
                    input.largest_excess_in_std,
                    input.samples_outside,
                    contributions(input, sindy.as_ref())
                )
            });
            Some(format!(
                "{label} {} of {}{detail}",
                coverage.samples_outside, coverage.samples
            ))
        })
        .collect();
    (!parts.is_empty()).then(|| {
        format!(
            "LeARN query samples with an input outside the range of the meta-training inputs \
             (the networks extrapolate there), with the generalisation MSE of each method over the \
             query samples inside and outside that range: {}.",
            parts.join("; ")
        )
    })
}

/// What the samples outside on `input` add to each method's generalisation MSE (SINDy's from its
/// own coverage of the same samples), e.g. ", which add 0.126 to LeARN's MSE and 0.020 to
/// SINDy's"; empty without the errors.
fn contributions(input: &learn::InputCoverage, sindy: Option<&RangeCoverage>) -> String {
    let Some(learn) = input.contribution_to_mse else {
        return String::new();
    };
    let sindy = sindy
        .and_then(|coverage| coverage.inputs.iter().find(|i| i.input == input.input))
        .and_then(|i| i.contribution_to_mse);
    match sindy {
        Some(sindy) => {
            format!(", which add {learn:.3} to LeARN's MSE and {sindy:.3} to SINDy's")
        }
        None => format!(", which add {learn:.3} to LeARN's MSE"),
    }
}

/// Column `j` of two stacked matrices.
fn stacked_column(top: &Mat<f64>, bottom: &Mat<f64>, j: usize) -> Vec<f64> {
    (0..top.nrows())
        .map(|i| top[(i, j)])
        .chain((0..bottom.nrows()).map(|i| bottom[(i, j)]))
        .collect()
}

/// Every column of two stacked matrices (support rows, then query rows).
pub(crate) fn stacked_columns(top: &Mat<f64>, bottom: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..top.ncols())
        .map(|j| stacked_column(top, bottom, j))
        .collect()
}

/// The qualitative figure of one cell (time and ground truth over both segments, one trace per
/// method) and its file name.
pub(crate) fn cell_figure(
    formulation: Formulation,
    condition: &Condition,
    support: &Segment,
    query: &Segment,
    methods: Vec<MethodTrace>,
) -> Result<(String, QualitativeFigure)> {
    let figure = QualitativeFigure {
        table: formulation.name().to_string(),
        condition: condition.label().to_string(),
        time: support.time.iter().chain(&query.time).copied().collect(),
        split: support.len(),
        outputs: formulation
            .target_names()
            .iter()
            .map(|o| OutputAxis::for_target(o))
            .collect(),
        truth: stacked_columns(&support.targets, &query.targets),
        methods,
    };
    figure.validate()?;
    Ok((
        figure_file_name(formulation.name(), condition.label()),
        figure,
    ))
}

/// The figure's file name: table and condition label, with anything unusual replaced by `-`.
pub fn figure_file_name(table: &str, label: &str) -> String {
    let clean: String = label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect();
    format!("{table}_{clean}.svg")
}

fn figure(cell: &Cell, learn_result: &CellResult) -> Result<(String, QualitativeFigure)> {
    let methods = vec![
        MethodTrace {
            method: "SINDy".to_string(),
            prediction: stacked_columns(
                &cell.sindy.support_prediction,
                &cell.sindy.query_prediction,
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
    cell_figure(
        cell.formulation,
        cell.condition,
        &cell.support,
        &cell.query,
        methods,
    )
}

fn record(cell: &Cell, learn_results: &[Vec<CellResult>], index: usize) -> Result<CellRecord> {
    let first = &learn_results[0][index];
    let model = &first.model;
    let support_inputs = model.standardiser.apply(&row_major(&cell.support.inputs()));
    let explanation = explain(
        cell.formulation,
        &model.architecture,
        &first.adapted_parameters,
        &support_inputs,
        EquationRule::default(),
    );
    let mse = learn_mse(learn_results, index);
    let sindy_split = sindy_query_coverage(cell, first);
    Ok(CellRecord {
        table: cell.formulation.name().to_string(),
        condition: cell.condition.name.clone(),
        label: cell.condition.label().to_string(),
        flight: cell.flight.file.clone(),
        support_rows: [cell.support.rows.start, cell.support.rows.end],
        query_rows: [cell.query.rows.start, cell.query.rows.end],
        sindy: SindyCell {
            adapt: cell.sindy.support_mse,
            r#gen: cell.sindy.query_mse,
            equations: cell.sindy.model.equations(3),
            gen_inside_range: sindy_split.as_ref().and_then(|c| c.mse_inside),
            gen_outside_range: sindy_split.as_ref().and_then(|c| c.mse_outside),
            gen_added_outside_range: sindy_split
                .iter()
                .flat_map(|c| &c.inputs)
                .filter_map(|input| {
                    Some(InputContribution {
                        input: input.input.clone(),
                        contribution_to_mse: input.contribution_to_mse?,
                    })
                })
                .collect(),
        },
        learn: LearnCell {
            adapt: mse.adaptation,
            r#gen: mse.generalisation,
            seeds: learn_results
                .iter()
                .map(|results| {
                    let result = &results[index];
                    LearnSeedCell {
                        seed: result.summary.seed,
                        adapt: result.summary.adapt_mse,
                        r#gen: result.summary.gen_mse,
                        unadapted_adapt: result.summary.unadapted_adapt_mse,
                        unadapted_gen: result.summary.unadapted_gen_mse,
                        final_meta_loss: result.model.meta_loss_history.last().copied(),
                    }
                })
                .collect(),
            explanation,
            support_coverage: seed_mean_coverage(learn_results, index, |s| &s.support_coverage),
            query_coverage: seed_mean_coverage(learn_results, index, |s| &s.query_coverage),
        },
    })
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

fn provenance(
    config: &CheckedRunConfig,
    root: &Path,
    flights: &[EvaluationFlight],
    learn_results: &[Vec<CellResult>],
    protocol: String,
) -> Result<Provenance> {
    let mut data_files: Vec<DataFile> = flights.iter().map(|f| f.file.clone()).collect();
    for result in learn_results.iter().flatten() {
        data_files.extend(result.model.data_files.iter().cloned());
        data_files.push(result.summary.evaluation_file.clone());
    }
    data_files.sort_by(|a, b| a.path.cmp(&b.path));
    data_files.dedup_by(|a, b| a.path == b.path);
    let run_config_path = config
        .path
        .strip_prefix(root)
        .map(PathBuf::from)
        .unwrap_or_else(|_| config.path.clone());
    Ok(Provenance {
        git_commit: git_commit(root),
        run_config: FileRef {
            path: run_config_path,
            sha256: config.sha256.clone(),
        },
        conditions: file_ref(&config.raw.conditions, &config.conditions_path)?,
        published: file_ref(&config.raw.published, &config.published_path)?,
        learn_config: file_ref(&config.raw.learn.config, &config.learn_config_path)?,
        learn_overrides: config.raw.learn.overrides.clone(),
        data_files,
        protocol,
        split: config.raw.split,
        derivative: config.raw.derivative,
        seeds: config.raw.learn.seeds.clone(),
        sindy: config.raw.sindy.clone(),
        learn: config.learn.get().clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A still flight of `n` samples at 50 Hz read from `path`.
    fn still_flight(path: &str, n: usize) -> FlightLog {
        FlightLog {
            path: PathBuf::from(path),
            meta: None,
            time: (0..n).map(|k| k as f64 * 0.02).collect(),
            position: vec![[0.0; 3]; n],
            velocity: vec![[0.0; 3]; n],
            quaternion: vec![[0.0, 0.0, 0.0, 1.0]; n],
            rotation: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; n],
            body_rate: vec![[0.0; 3]; n],
            thrust_setpoint: vec![0.5; n],
            hover_throttle: vec![0.5; n],
            motor_command: vec![[1500.0; 4]; n],
            position_desired: None,
            velocity_desired: None,
            attitude_setpoint: None,
            residual_force: None,
        }
    }

    #[test]
    fn a_flight_too_short_to_split_is_named() {
        let short = still_flight("/data/experiment/short.csv", 3);
        let message = flight_segments(
            &short,
            Formulation::Full,
            SplitSpec::Halves,
            Derivative::Forward,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            message,
            "/data/experiment/short.csv: split: 3 rows are too few to split (1 / 2)"
        );
        let (support, query) = flight_segments(
            &still_flight("long.csv", 10),
            Formulation::Full,
            SplitSpec::Halves,
            Derivative::Forward,
        )
        .unwrap();
        assert_eq!((support.rows, query.rows), (0..5, 5..10));
    }

    #[test]
    fn figure_names_are_safe() {
        assert_eq!(figure_file_name("full", "70psin20"), "full_70psin20.svg");
        assert_eq!(
            figure_file_name("attitude", "8 m/s gust"),
            "attitude_8-m-s-gust.svg"
        );
    }

    #[test]
    fn stacked_columns_follow_time_order() {
        let top = Mat::from_fn(2, 2, |i, j| (i * 10 + j) as f64);
        let bottom = Mat::from_fn(1, 2, |_, j| 100.0 + j as f64);
        assert_eq!(stacked_column(&top, &bottom, 1), vec![1.0, 11.0, 101.0]);
        assert_eq!(mean([1.0, 2.0, 6.0].into_iter()), 3.0);
    }

    #[test]
    fn the_coverage_note_names_the_input_that_goes_farthest() {
        let input = |input: &str, samples_outside, largest_excess_in_std| learn::InputCoverage {
            input: input.to_string(),
            samples_outside,
            largest_excess_in_std,
            contribution_to_mse: (samples_outside > 0).then_some(0.125),
        };
        let inside = RangeCoverage {
            samples: 10,
            samples_outside: 0,
            inputs: vec![input("w_x", 0, 0.0), input("w_z", 0, 0.0)],
            mse_inside: Some(0.5),
            mse_outside: None,
        };
        let outside = RangeCoverage {
            samples: 10,
            samples_outside: 3,
            inputs: vec![input("w_x", 2, 6.5), input("w_z", 3, 9.61)],
            mse_inside: Some(0.25),
            mse_outside: Some(2.5),
        };
        let mut sindy = RangeCoverage {
            mse_inside: Some(0.5),
            mse_outside: Some(1.25),
            ..outside.clone()
        };
        sindy.inputs[1].contribution_to_mse = Some(0.0703125);
        let note = coverage_note(
            [
                ("35wind", Some(&inside), None),
                ("100wind", Some(&outside), Some(sindy)),
                ("70wind", Some(&outside), None),
                ("new", None, None),
            ]
            .into_iter(),
        )
        .unwrap();
        assert!(
            note.ends_with(
                ": 35wind 0 of 10; \
                 100wind 3 of 10 (farthest: w_z by 9.6 std on 3 samples, which add 0.125 to LeARN's MSE and 0.070 to SINDy's; MSE inside / outside: LeARN 0.250 / 2.500, SINDy 0.500 / 1.250); \
                 70wind 3 of 10 (farthest: w_z by 9.6 std on 3 samples, which add 0.125 to LeARN's MSE; MSE inside / outside: LeARN 0.250 / 2.500)."
            ),
            "{note}"
        );
        assert_eq!(coverage_note([("35wind", None, None)].into_iter()), None);
    }
}
