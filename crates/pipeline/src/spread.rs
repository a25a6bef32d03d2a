//! The seed-to-seed spread of the LeARN columns (`learn meta-train --seed-spread`): every cell
//! meta-trained and adapted once per seed of the configuration's `spread_seeds`, the spread of each
//! cell's MSE over the seeds written as one JSON file. Its work is the sweep of
//! [`Experiment::work_items`]; the unsharded run, each shard and `learn merge` write the file
//! through [`spread_document`].

use std::path::Path;

use learn::Formulation;
use learn::LearnConfig;
use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::error::{PipelineError, Result};
use crate::experiment::{CellSummary, Experiment, SpreadCell, WorkItem, spread_cells};
use crate::flights::Protocol;
use crate::progress::Progress;
use crate::shard::{ItemResult, ShardFile, ShardSpec, Sweep, SweepKind};

/// What the spread file takes from the configuration: the same for every shard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpreadContext {
    pub protocol: Protocol,
    /// The LeARN configuration (as read, its `spread_seeds` included).
    pub config: LearnConfig,
    pub seeds: Vec<u64>,
    /// The command that made it, as the file records it.
    pub how: String,
    /// The SHA-256 of the configuration and conditions files.
    pub input_sha256: Vec<String>,
}

/// A shard of the seed spread: each item's cells.
pub type SpreadShard = ShardFile<SpreadContext, Vec<CellSummary>>;

/// The spread's work: every cell of `formulations` × every evaluation condition × every spread
/// seed of the experiment's configuration. `config_file` is the configuration as named on the
/// command line (recorded in the file); `inputs` are the files read besides the flights.
pub fn spread_sweep(
    experiment: &Experiment,
    formulations: &[Formulation],
    config_file: &Path,
    inputs: &[&Path],
) -> Result<Sweep<SpreadContext>> {
    let config = experiment.config().get().clone();
    let seeds = config.spread_seeds.clone();
    let input_sha256 = inputs
        .iter()
        .map(|path| data::file_sha256(path).map_err(PipelineError::from))
        .collect::<Result<_>>()?;
    Ok(Sweep {
        kind: SweepKind::SeedSpread,
        context: SpreadContext {
            protocol: experiment.protocol(),
            how: format!(
                "learn meta-train --seed-spread --config {} (every cell meta-trained and adapted once per seed; std is the sample standard deviation over seeds)",
                config_file.display()
            ),
            config,
            input_sha256,
            seeds: seeds.clone(),
        },
        items: experiment.work_items(formulations, &seeds),
        data_files: experiment.data_files(),
    })
}

/// Runs the items of `shard` of the spread `sweep`, telling `progress` of each cell as it ends.
pub fn run_spread(
    experiment: &Experiment,
    sweep: &Sweep<SpreadContext>,
    shard: ShardSpec,
    progress: &dyn Progress,
) -> Result<Vec<ItemResult<Vec<CellSummary>>>> {
    sweep.run(shard, |item| {
        let cells = experiment.run_item(item, progress)?;
        Ok(cells.into_iter().map(|cell| cell.summary).collect())
    })
}

/// The spread of every cell and the spread file's document, from every item's summaries
/// (`summaries[i]` of `items[i]`).
pub fn spread_document(
    context: &SpreadContext,
    items: &[WorkItem],
    summaries: &[Vec<CellSummary>],
) -> (Vec<SpreadCell>, serde_json::Value) {
    let spread = spread_cells(items, summaries);
    let document = json!({
        "what": "seed-to-seed spread of the LeARN adaptation and generalisation MSE per table cell",
        "how": context.how,
        "protocol": context.protocol.name(),
        "config": context.config,
        "seeds": context.seeds,
        "cells": spread,
    });
    (spread, document)
}
