//! `make ablations`: every variant of `experiments/variants.json` on every formulation ×
//! evaluation condition, over the configuration's seeds (see [`crate::VariantsConfig`] for the
//! variants and the protocol).
//!
//! The work is a sweep of (formulation, condition, seed) items ([`crate::WorkItem`]), each
//! evaluating every variant on its cell with its seed ([`AblationSeedOutcome`]); the first seed's
//! item also carries the cell's SINDy, noise floors, headline equations and figure. The
//! unsharded run, each shard and `learn merge` render the same results through the same code.

mod work;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::experiment::{Cells, WorkItem};
use learn::Formulation;
use report::NoiseFloor;
use report::{AblationRow, AblationTables, QualitativeFigure, SeedCell, VariantCell, VariantNote};
use serde::{Deserialize, Serialize};

use crate::error::{EvaluationError, Result, write_text};
use crate::progress::{Progress, Stage, Stopwatch};
use crate::segment::Segmentation;
use crate::shard::{ItemResult, MergedSweep, ShardFile, ShardProvenance, ShardSpec};
use crate::summary::StageTiming;
use crate::tables::ConditionName;
use crate::variants::{CheckedVariants, VariantsConfig};

use work::AblationsWork;

/// The whole ablation result (`results/ablations/ablations.json`). Its rows are `report`'s
/// [`AblationRow`]s; [`Ablations::tables`] is what `ablations.md` shows of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ablations {
    pub name: String,
    pub description: String,
    pub protocol: String,
    pub provenance: AblationProvenance,
    pub config: VariantsConfig,
    pub rows: Vec<AblationRow>,
}

impl Ablations {
    /// The ablation tables as `report` renders them ([`report::ablations_markdown`]).
    pub fn tables(&self) -> AblationTables<'_> {
        let config = &self.config;
        AblationTables {
            name: &self.name,
            description: &self.description,
            protocol: &self.protocol,
            seeds: &config.seeds,
            headline: &config.headline,
            headline_equations_of: config
                .equations_variant(&config.headline)
                .unwrap_or(&config.headline),
            figure_variant: config.figure_variant.as_deref(),
            variants: config
                .variants
                .iter()
                .map(|v| VariantNote {
                    name: &v.name,
                    description: &v.description,
                })
                .collect(),
            rows: &self.rows,
        }
    }
}

/// Where the ablation numbers come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AblationProvenance {
    /// The last commit that changed an input of the run (see [`crate::git_commit`]).
    pub git_commit: String,
    /// The evaluation flights (relative to the data directory) and their SHA-256.
    pub data_files: Vec<learn::DataFile>,
    /// The LeARN configuration the learned-basis variants were meta-trained with (after
    /// `learn_overrides`), when any learned-basis variant ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub learn_config: Option<learn::LearnConfig>,
}

/// Everything `make ablations` writes.
pub struct AblationsOutcome {
    pub ablations: Ablations,
    pub figures: Vec<(String, QualitativeFigure)>,
}

/// What rendering the ablations takes from the configuration: the same for every shard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AblationsContext {
    pub config: VariantsConfig,
    /// How every flight is cut (the run configuration's `split` and `derivative`).
    pub segmentation: Segmentation,
    /// The cells (formulation × evaluation condition), in row order.
    pub cells: Vec<AblationCell>,
    /// The evaluation flights (relative to the data directory), in row order of the conditions.
    pub evaluation_files: Vec<learn::DataFile>,
    /// See [`AblationProvenance::learn_config`].
    pub learn_config: Option<learn::LearnConfig>,
    /// The SHA-256 of every file the ablations read besides the flights.
    pub input_sha256: Vec<String>,
}

/// One row of the ablation tables, as configured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AblationCell {
    pub formulation: Formulation,
    pub condition: ConditionName,
    /// The paper's numbers for the cell, when it has them.
    pub published: Option<report::MethodPair>,
}

/// Every variant on one cell with one seed: a work item's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AblationSeedOutcome {
    /// One per variant, in declaration order.
    pub variants: Vec<SeedCell>,
    /// With the first seed only: the cell's parts that do not vary with the seed, and those the
    /// tables take from the first seed.
    pub first_seed: Option<AblationCellDetail>,
}

/// See [`AblationSeedOutcome::first_seed`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AblationCellDetail {
    /// Our SINDy with the run configuration's settings.
    pub sindy: report::Mse,
    pub noise_floor_support: NoiseFloor,
    pub noise_floor_query: NoiseFloor,
    /// See [`AblationRow::headline_equations`].
    pub headline_equations: Vec<String>,
    /// The figure of the configuration's `figure_variant`, if any: file name and contents.
    pub figure: Option<(String, QualitativeFigure)>,
}

/// A shard of the ablations: each (cell, seed) item's variants.
pub type AblationsShard = ShardFile<AblationsContext, AblationSeedOutcome>;

/// Runs every variant on every cell and seed; `progress` is told of the stages (see
/// [`run_variants_shard`]) and of each item as it ends.
pub fn run_variants(
    config: &CheckedVariants,
    data_dir: &Path,
    progress: &dyn Progress,
) -> Result<AblationsOutcome> {
    let (work, results, _) = plan_and_run(config, data_dir, progress, ShardSpec::WHOLE)?;
    let results: Vec<AblationSeedOutcome> = results.into_iter().map(|r| r.result).collect();
    render_ablations(
        &work.sweep.context,
        &work.sweep.items,
        &results,
        crate::git_commit(&config.root),
    )
}

/// Runs shard `shard` of the ablations (see [`run_variants`]); the shard records the times of
/// the stages.
pub fn run_variants_shard(
    config: &CheckedVariants,
    data_dir: &Path,
    progress: &dyn Progress,
    shard: ShardSpec,
) -> Result<AblationsShard> {
    let (work, results, stages) = plan_and_run(config, data_dir, progress, shard)?;
    let provenance = ShardProvenance::here(&config.root, stages);
    work.sweep.shard_file(shard, results, provenance)
}

/// The results of the items of `shard`, and the stages' times: "load flights, cut the cells", then
/// "variants" (one unit of progress per item).
type ShardRun<'c> = (
    AblationsWork<'c>,
    Vec<ItemResult<AblationSeedOutcome>>,
    Vec<StageTiming>,
);

/// Plans the ablations and runs the items of `shard`.
fn plan_and_run<'c>(
    config: &'c CheckedVariants,
    data_dir: &Path,
    progress: &dyn Progress,
    shard: ShardSpec,
) -> Result<ShardRun<'c>> {
    let mut stopwatch = Stopwatch::new(progress);
    let work = stopwatch.time("load flights, cut the cells", || {
        AblationsWork::plan(config, data_dir)
    })?;
    let items = shard.positions(work.sweep.items.len()).len();
    let stage = Stage::counting("variants", "variants", items);
    let results = stopwatch.time(stage, || work.run_items(shard, progress))?;
    Ok((work, results, stopwatch.timings()))
}

/// The ablations of merged shards, rendered as [`run_variants`] renders them.
pub fn merged_ablations(
    merged: MergedSweep<AblationsContext, AblationSeedOutcome>,
) -> Result<AblationsOutcome> {
    render_ablations(
        &merged.context,
        &merged.items,
        &merged.results,
        merged.git_commit,
    )
}

/// The ablations of `context` from every item's outcome (`results[i]` of `items[i]`), at the
/// commit the work was done at.
fn render_ablations(
    context: &AblationsContext,
    items: &[WorkItem],
    results: &[AblationSeedOutcome],
    git_commit: String,
) -> Result<AblationsOutcome> {
    let config = &context.config;
    let by_item: BTreeMap<(Formulation, &Cells, u64), &AblationSeedOutcome> = items
        .iter()
        .zip(results)
        .map(|(item, result)| ((item.formulation, &item.cells, item.seed), result))
        .collect();
    let mut rows = Vec::with_capacity(context.cells.len());
    let mut figures = Vec::new();
    for cell in &context.cells {
        let cells = Cells::Condition(cell.condition.name.clone());
        let per_seed = config
            .seeds
            .iter()
            .map(|&seed| {
                by_item
                    .get(&(cell.formulation, &cells, seed))
                    .copied()
                    .ok_or_else(|| EvaluationError::Mismatch {
                        what: format!(
                            "{} {} seed {seed}",
                            cell.formulation.name(),
                            cell.condition.label
                        ),
                        message: "no ablation result".to_string(),
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        let detail = per_seed[0]
            .first_seed
            .as_ref()
            .ok_or_else(|| EvaluationError::Mismatch {
                what: format!("{} {}", cell.formulation.name(), cell.condition.label),
                message: "the first seed's result has no cell detail".to_string(),
            })?;
        figures.extend(detail.figure.clone());
        rows.push(ablation_row(context, cell, &per_seed, detail));
    }
    Ok(AblationsOutcome {
        ablations: Ablations {
            name: config.name.clone(),
            description: config.description.clone(),
            provenance: AblationProvenance {
                git_commit,
                data_files: context.evaluation_files.clone(),
                learn_config: context.learn_config.clone(),
            },
            protocol: format!(
                "{}; every choice by blocked cross-validation inside the support segment",
                context.segmentation.describe()
            ),
            config: config.clone(),
            rows,
        },
        figures,
    })
}

/// One row: every variant summarised over the seeds (`per_seed`, in the configuration's order).
fn ablation_row(
    context: &AblationsContext,
    cell: &AblationCell,
    per_seed: &[&AblationSeedOutcome],
    detail: &AblationCellDetail,
) -> AblationRow {
    let variants = context
        .config
        .variants
        .iter()
        .enumerate()
        .map(|(index, spec)| {
            let seeds = per_seed.iter().map(|s| s.variants[index].clone()).collect();
            (spec.name.clone(), summarise(seeds))
        })
        .collect();
    let pair = cell.published;
    AblationRow {
        table: cell.formulation.name().to_string(),
        condition: cell.condition.label.clone(),
        target: pair.map(|p| p.sindy.generalisation.min(p.learn.generalisation)),
        published: pair,
        sindy: detail.sindy,
        noise_floor_support: detail.noise_floor_support,
        noise_floor_query: detail.noise_floor_query,
        variants,
        headline_equations: detail.headline_equations.clone(),
    }
}

fn summarise(seeds: Vec<SeedCell>) -> VariantCell {
    let stats = |values: Vec<f64>| -> (f64, f64) {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let variance = if values.len() > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        (mean, variance.sqrt())
    };
    let (adaptation, adapt_std) = stats(seeds.iter().map(|s| s.adaptation).collect());
    let (generalisation, gen_std) = stats(seeds.iter().map(|s| s.generalisation).collect());
    VariantCell {
        adaptation,
        generalisation,
        adapt_std,
        gen_std,
        seeds,
    }
}

/// Writes `ablations.json`, `ablations.md` and the figures under `dir`; returns the paths.
pub fn write_ablations(outcome: &AblationsOutcome, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let json = dir.join("ablations.json");
    let text = serde_json::to_string_pretty(&outcome.ablations).expect("plain data serialises");
    write_text(&json, &format!("{text}\n"))?;
    written.push(json);
    let md = dir.join("ablations.md");
    write_text(
        &md,
        &report::ablations_markdown(&outcome.ablations.tables()),
    )?;
    written.push(md);
    for (file, figure) in &outcome.figures {
        let path = dir.join("figures").join(file);
        figure.save_svg(&path)?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_committed_ablations_are_read_and_written_back_byte_for_byte() {
        // Every typed part of the file (the variants' choices among them) keeps its bytes.
        let text = include_str!("../../../../results/ablations/ablations.json");
        let ablations: Ablations = serde_json::from_str(text).unwrap();
        let written = serde_json::to_string_pretty(&ablations).unwrap() + "\n";
        assert!(written == text, "ablations.json is not written as read");
        assert!(ablations.rows.iter().any(|row| {
            row.variants
                .values()
                .any(|cell| cell.seeds.iter().any(|s| s.chosen.contains_key("variant")))
        }));
    }
}
