//! The seed-to-seed spread of the LeARN columns (`learn meta-train --seed-spread`): every cell
//! meta-trained and adapted once per seed of the configuration's `spread_seeds`, the spread of each
//! cell's MSE over the seeds written as one JSON file. Its work is the sweep of
//! [`Experiment::work_items`]; the unsharded run, each shard and `learn merge` write the file
//! through [`spread_document`].

use std::path::Path;

use learn::Formulation;
use learn::LearnConfig;
use serde::{Deserialize, Serialize};

use crate::error::{EvaluationError, Result};
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
        .map(|path| data::file_sha256(path).map_err(EvaluationError::from))
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

/// The spread file (`--spread-out`). Written through [`serde_json::Value`] (see
/// [`SpreadDocument::to_json`]), so its keys are sorted at every level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SpreadDocument {
    /// Always [`SPREAD_WHAT`].
    pub what: String,
    /// The command that made it.
    pub how: String,
    pub protocol: Protocol,
    /// The LeARN configuration (as read, its `spread_seeds` included).
    pub config: LearnConfig,
    pub seeds: Vec<u64>,
    /// Every cell's spread, in table order.
    pub cells: Vec<SpreadCell>,
}

/// What a spread file holds, as it says.
pub const SPREAD_WHAT: &str =
    "seed-to-seed spread of the LeARN adaptation and generalisation MSE per table cell";

impl SpreadDocument {
    /// The file's text: pretty JSON with the keys sorted at every level (the layout the spread
    /// file has always had) and a final newline.
    pub fn to_json(&self) -> String {
        let value = serde_json::to_value(self).expect("plain data serialises");
        serde_json::to_string_pretty(&value).expect("plain data serialises") + "\n"
    }
}

/// The spread file's document, from every item's summaries (`summaries[i]` of `items[i]`).
pub fn spread_document(
    context: &SpreadContext,
    items: &[WorkItem],
    summaries: &[Vec<CellSummary>],
) -> SpreadDocument {
    SpreadDocument {
        what: SPREAD_WHAT.to_string(),
        how: context.how.clone(),
        protocol: context.protocol,
        config: context.config.clone(),
        seeds: context.seeds.clone(),
        cells: spread_cells(items, summaries),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::Spread;
    use serde_json::json;

    #[test]
    fn the_spread_file_is_written_with_its_keys_sorted_at_every_level() {
        let config: LearnConfig =
            serde_json::from_str(include_str!("../../../experiments/learn.json")).unwrap();
        let document = SpreadDocument {
            what: SPREAD_WHAT.to_string(),
            how: "learn meta-train --seed-spread".to_string(),
            protocol: Protocol::LeaveConditionOut,
            config: config.clone(),
            seeds: vec![1, 2],
            cells: vec![SpreadCell {
                formulation: Formulation::Full,
                condition: "70p20sint".to_string(),
                label: "70psin20".to_string(),
                protocol: Protocol::LeaveConditionOut,
                seeds: vec![1, 2],
                generalisation: Spread::of(vec![0.25, 0.5]),
                adaptation: Spread::of(vec![0.125, 0.375]),
            }],
        };
        // The document as the file was always built: a JSON object of these keys (serde_json
        // without `preserve_order` keeps every object's keys sorted).
        let built = json!({
            "what": SPREAD_WHAT,
            "how": document.how,
            "protocol": "leave-condition-out",
            "config": config,
            "seeds": [1, 2],
            "cells": document.cells,
        });
        let text = document.to_json();
        assert_eq!(text, serde_json::to_string_pretty(&built).unwrap() + "\n");
        // Sorted at the top and inside: `adapt_mse` before `condition` in a cell.
        let top: Vec<&str> = ["cells", "config", "how", "protocol", "seeds", "what"].to_vec();
        let positions: Vec<usize> = top
            .iter()
            .map(|key| text.find(&format!("\n  \"{key}\"")).unwrap())
            .collect();
        assert!(positions.windows(2).all(|w| w[0] < w[1]), "{positions:?}");
        assert!(text.find("\"adapt_mse\"").unwrap() < text.find("\"condition\"").unwrap());
    }
}
