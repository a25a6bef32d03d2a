//! Assembling a reproduce run's results: from its context (what the configuration says) and its
//! work items' results ([`LearnCellOutcome`] per cell and seed) to the typed tables, figures and
//! `summary.json` (every number averaged over seeds, every cell in table order); the text under a
//! table is `report`'s ([`report::coverage_note`]). The unsharded run and `learn merge` both
//! assemble through [`render`], so their outputs are the same bytes.

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::experiment::CellSummary;
use crate::sindy_column::SindyConfig;
use data::SplitSpec;
use learn::{DataFile, Explanation, Formulation, LearnConfig, RangeCoverage};
use report::{
    FarthestInput, Mse, PublishedTables, QualitativeFigure, QueryCoverage, ResultsTable, Row,
};
use serde::{Deserialize, Serialize};
use sindy::Derivative;

use crate::error::{EvaluationError, Result};
use crate::summary::{
    CellRecord, FileRef, InputContribution, LearnCell, LearnSeedCell, Provenance, SUMMARY_FORMAT,
    SindyCell, Summary,
};

/// An evaluation condition as the tables show it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConditionName {
    /// The file name, e.g. `70p20sint`.
    pub name: String,
    /// As printed, e.g. `70psin20`.
    pub label: String,
}

/// What a reproduce run's rendering takes from its configuration: the same for every shard of
/// one run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReproduceContext {
    /// The run configuration's name and description.
    pub run: String,
    pub description: String,
    /// The tables, in order.
    pub formulations: Vec<Formulation>,
    /// The evaluation conditions, in row order.
    pub conditions: Vec<ConditionName>,
    pub published: PublishedTables,
    /// The LeARN protocol the run resolved (`paper` or `leave-condition-out`).
    pub protocol: String,
    /// The files the configuration names and its values, as `summary.json` records them.
    pub inputs: RunInputs,
    /// The SHA-256 of every file the run reads besides the flights (the variants file too).
    pub input_sha256: Vec<String>,
    /// The evaluation flights (relative to the data directory), in row order.
    pub evaluation_files: Vec<DataFile>,
}

/// The part of [`Provenance`] the configuration decides.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunInputs {
    pub run_config: FileRef,
    pub conditions: FileRef,
    pub published: FileRef,
    pub learn_config: FileRef,
    pub learn_overrides: serde_json::Value,
    pub split: SplitSpec,
    pub derivative: Derivative,
    pub seeds: Vec<u64>,
    pub sindy: SindyConfig,
    pub learn: LearnConfig,
}

impl ReproduceContext {
    /// The files the run writes below its results folder (see [`crate::result_files`]).
    pub fn result_files(&self) -> Vec<PathBuf> {
        let labels: Vec<&str> = self.conditions.iter().map(|c| c.label.as_str()).collect();
        crate::output::result_files_of(&self.formulations, &labels)
    }

    /// The files the run writes in its LaTeX folder.
    pub fn latex_files(&self) -> Vec<PathBuf> {
        crate::output::latex_files_of(&self.formulations)
    }
}

/// LeARN on one cell with one seed, as rendering uses it (a work item's result is one per cell it
/// serves).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnCellOutcome {
    pub summary: CellSummary,
    /// Mean meta-loss of the last meta-iteration.
    pub final_meta_loss: Option<f64>,
    /// The model's meta-training flights.
    pub meta_training_files: Vec<DataFile>,
    /// With the first seed only: the cell's parts that do not vary with the seed, and those the
    /// tables take from the first seed.
    pub first_seed: Option<CellDetail>,
}

/// See [`LearnCellOutcome::first_seed`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellDetail {
    pub flight: DataFile,
    pub support_rows: [usize; 2],
    pub query_rows: [usize; 2],
    pub sindy: SindyOutcome,
    /// The first seed's adapted model, explained over the support segment.
    pub explanation: Explanation,
    /// The qualitative figure's file name and contents (SINDy and the first seed's LeARN).
    pub figure: (String, QualitativeFigure),
    /// The variants file's `reproduce` columns, with the first seed's model.
    pub variant_columns: BTreeMap<String, Mse>,
}

/// SINDy on one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SindyOutcome {
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
    /// Three decimals.
    pub equations: Vec<String>,
    /// SINDy's query predictions split as LeARN's query coverage (first seed's range).
    pub query_coverage: Option<RangeCoverage>,
}

/// One cell's outcomes: the first seed's detail and every seed's LeARN, in seed order.
struct CellOutcomes<'a> {
    formulation: Formulation,
    condition: &'a ConditionName,
    detail: &'a CellDetail,
    seeds: Vec<&'a LearnCellOutcome>,
}

/// What a run renders: tables, figures (file name, figure) and the summary.
pub type Rendered = (Vec<ResultsTable>, Vec<(String, QualitativeFigure)>, Summary);

/// The tables, figures and summary of a run with `context`, from every work item's outcomes (in
/// any order) and the commit the work was done at.
pub fn render(
    context: &ReproduceContext,
    outcomes: &[LearnCellOutcome],
    git_commit: String,
) -> Result<Rendered> {
    let cells = gather(context, outcomes)?;
    let mut tables: Vec<ResultsTable> = context
        .formulations
        .iter()
        .map(|&formulation| table(context, formulation, &cells))
        .collect();
    for table in &mut tables {
        table.attach_published(&context.published);
    }
    let figures = cells.iter().map(|c| c.detail.figure.clone()).collect();
    let records = cells.iter().map(record).collect();
    let summary = Summary {
        format: SUMMARY_FORMAT.to_string(),
        run: context.run.clone(),
        description: context.description.clone(),
        provenance: provenance(context, outcomes, git_commit),
        tables: tables.clone(),
        cells: records,
    };
    Ok((tables, figures, summary))
}

/// The outcomes of each cell in table order (formulation, then condition), seeds in the
/// configuration's order; an error naming a cell or seed without an outcome.
fn gather<'a>(
    context: &'a ReproduceContext,
    outcomes: &'a [LearnCellOutcome],
) -> Result<Vec<CellOutcomes<'a>>> {
    let by_cell: BTreeMap<(Formulation, &str, u64), &LearnCellOutcome> = outcomes
        .iter()
        .map(|o| {
            let s = &o.summary;
            ((s.formulation, s.condition.as_str(), s.seed), o)
        })
        .collect();
    let mut cells = Vec::new();
    for &formulation in &context.formulations {
        for condition in &context.conditions {
            let missing = |seed: u64, what: &str| EvaluationError::Mismatch {
                what: format!("{} {} seed {seed}", formulation.name(), condition.label),
                message: format!("no {what} among the results"),
            };
            let seeds = context
                .inputs
                .seeds
                .iter()
                .map(|&seed| {
                    by_cell
                        .get(&(formulation, condition.name.as_str(), seed))
                        .copied()
                        .ok_or_else(|| missing(seed, "LeARN cell"))
                })
                .collect::<Result<Vec<_>>>()?;
            let first_seed = context.inputs.seeds[0];
            let detail = seeds[0]
                .first_seed
                .as_ref()
                .ok_or_else(|| missing(first_seed, "first-seed detail"))?;
            cells.push(CellOutcomes {
                formulation,
                condition,
                detail,
                seeds,
            });
        }
    }
    Ok(cells)
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / count as f64
}

/// The LeARN errors of a cell, averaged over seeds.
fn learn_mse(cell: &CellOutcomes) -> Mse {
    Mse {
        adaptation: mean(cell.seeds.iter().map(|s| s.summary.adaptation)),
        generalisation: mean(cell.seeds.iter().map(|s| s.summary.generalisation)),
    }
}

/// A cell's coverage (`field` of each seed's summary) with LeARN's errors averaged over the seeds,
/// as its MSE is; the first seed's if the seeds' counts disagree.
fn seed_mean_coverage(
    cell: &CellOutcomes,
    field: fn(&CellSummary) -> &Option<RangeCoverage>,
) -> Option<RangeCoverage> {
    let per_seed: Option<Vec<&RangeCoverage>> = cell
        .seeds
        .iter()
        .map(|seed| field(&seed.summary).as_ref())
        .collect();
    let per_seed = per_seed?;
    RangeCoverage::mean(&per_seed).or_else(|| per_seed.first().map(|c| (*c).clone()))
}

/// The table of `formulation` (without the published numbers): one row per condition, the
/// variant columns after LeARN's, the coverage note under it.
fn table(
    context: &ReproduceContext,
    formulation: Formulation,
    cells: &[CellOutcomes],
) -> ResultsTable {
    let cells: Vec<&CellOutcomes> = cells
        .iter()
        .filter(|c| c.formulation == formulation)
        .collect();
    let rows = cells
        .iter()
        .map(|cell| {
            let sindy = &cell.detail.sindy;
            let mut row = Row::new(
                &cell.condition.label,
                Mse {
                    adaptation: sindy.adaptation,
                    generalisation: sindy.generalisation,
                },
                learn_mse(cell),
            );
            row.variants.extend(cell.detail.variant_columns.clone());
            row
        })
        .collect();
    let learn_coverages: Vec<Option<RangeCoverage>> = cells
        .iter()
        .map(|cell| seed_mean_coverage(cell, |s| &s.query_coverage))
        .collect();
    let coverages = cells.iter().zip(&learn_coverages).map(|(cell, learn)| {
        (
            cell.condition.label.as_str(),
            learn.as_ref(),
            cell.detail.sindy.query_coverage.clone(),
        )
    });
    ResultsTable {
        table: formulation.name().to_string(),
        protocol: context.protocol.clone(),
        rows,
        notes: coverage_note(coverages).into_iter().collect(),
    }
}

/// The note under a table on how much of each query segment lies outside the range of the
/// meta-training inputs ([`report::coverage_note`]), from each cell's label, LeARN's coverage (over
/// the seeds) and SINDy's of the same samples; `None` if no cell has a range.
fn coverage_note<'a>(
    coverages: impl Iterator<Item = (&'a str, Option<&'a RangeCoverage>, Option<RangeCoverage>)>,
) -> Option<String> {
    let cells: Vec<Option<QueryCoverage>> = coverages
        .map(|(label, learn, sindy)| Some(query_coverage(label, learn?, sindy.as_ref())))
        .collect();
    report::coverage_note(&cells)
}

/// A cell's query coverage as the note reports it: the input that goes farthest (with what the
/// samples outside on it add to each method's MSE), each method's MSE inside and outside.
fn query_coverage(
    label: &str,
    learn: &RangeCoverage,
    sindy: Option<&RangeCoverage>,
) -> QueryCoverage {
    let inside_outside = |coverage: &RangeCoverage| coverage.mse_inside.zip(coverage.mse_outside);
    let farthest = learn
        .inputs
        .iter()
        .filter(|input| input.samples_outside > 0)
        .max_by(|a, b| a.largest_excess_in_std.total_cmp(&b.largest_excess_in_std));
    QueryCoverage {
        label: label.to_string(),
        samples: learn.samples,
        samples_outside: learn.samples_outside,
        farthest: farthest.map(|input| FarthestInput {
            input: input.input.clone(),
            largest_excess_in_std: input.largest_excess_in_std,
            samples_outside: input.samples_outside,
            learn_added: input.contribution_to_mse,
            sindy_added: sindy
                .and_then(|coverage| coverage.inputs.iter().find(|i| i.input == input.input))
                .and_then(|i| i.contribution_to_mse),
        }),
        learn_inside_outside: inside_outside(learn),
        sindy_inside_outside: sindy.and_then(inside_outside),
    }
}

fn record(cell: &CellOutcomes) -> CellRecord {
    let detail = cell.detail;
    let mse = learn_mse(cell);
    let sindy_split = detail.sindy.query_coverage.as_ref();
    CellRecord {
        table: cell.formulation.name().to_string(),
        condition: cell.condition.name.clone(),
        label: cell.condition.label.clone(),
        flight: detail.flight.clone(),
        support_rows: detail.support_rows,
        query_rows: detail.query_rows,
        sindy: SindyCell {
            adaptation: detail.sindy.adaptation,
            generalisation: detail.sindy.generalisation,
            equations: detail.sindy.equations.clone(),
            gen_inside_range: sindy_split.and_then(|c| c.mse_inside),
            gen_outside_range: sindy_split.and_then(|c| c.mse_outside),
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
            adaptation: mse.adaptation,
            generalisation: mse.generalisation,
            seeds: cell
                .seeds
                .iter()
                .map(|seed| LearnSeedCell {
                    seed: seed.summary.seed,
                    adaptation: seed.summary.adaptation,
                    generalisation: seed.summary.generalisation,
                    unadapted_adapt: seed.summary.unadapted_adaptation,
                    unadapted_gen: seed.summary.unadapted_generalisation,
                    final_meta_loss: seed.final_meta_loss,
                })
                .collect(),
            explanation: detail.explanation.clone(),
            support_coverage: seed_mean_coverage(cell, |s| &s.support_coverage),
            query_coverage: seed_mean_coverage(cell, |s| &s.query_coverage),
        },
    }
}

/// The summary's provenance: the context's inputs, the commit, and every flight read (evaluation
/// flights, each model's meta-training flights), sorted by path.
fn provenance(
    context: &ReproduceContext,
    outcomes: &[LearnCellOutcome],
    git_commit: String,
) -> Provenance {
    let mut data_files: Vec<DataFile> = context.evaluation_files.clone();
    for outcome in outcomes {
        data_files.extend(outcome.meta_training_files.iter().cloned());
        data_files.push(outcome.summary.evaluation_file.clone());
    }
    data_files.sort_by(|a, b| a.path.cmp(&b.path));
    data_files.dedup_by(|a, b| a.path == b.path);
    let inputs = context.inputs.clone();
    Provenance {
        git_commit,
        run_config: inputs.run_config,
        conditions: inputs.conditions,
        published: inputs.published,
        learn_config: inputs.learn_config,
        learn_overrides: inputs.learn_overrides,
        data_files,
        protocol: context.protocol.clone(),
        split: inputs.split,
        derivative: inputs.derivative,
        seeds: inputs.seeds,
        sindy: inputs.sindy,
        learn: inputs.learn,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
