//! The units of work of a sweep over cells and seeds: one [`WorkItem`] is one meta-training (one
//! formulation, one seed) and the evaluation cells it serves. The table runs, the seed spread and
//! their shards (`learn … --shard K/N`) all enumerate their work with [`Experiment::work_items`] and
//! run it with [`Experiment::run_item`] (LeARN on the item's cells, by the [`Runner`]), so a
//! sharded sweep does exactly the work of an unsharded one, item by item; each item depends on its
//! own seed only, never on which items ran beside it.

use std::fmt;

use learn::Formulation;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use std::sync::Arc;

use super::{CellResult, CellSummary, EvaluationCell, Experiment};
use crate::error::{EvaluationError, Result};
use crate::flights::Protocol;
use crate::progress::Progress;
use crate::runner::{Method, Outcome, Runner, item_cells};

/// The evaluation cells one meta-trained model serves.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Cells {
    /// One evaluation condition (its name): under `leave-condition-out` the model leaves it out.
    Condition(String),
    /// Every evaluation condition, in table order: under `paper` one model serves them all.
    Every,
}

/// One unit of work: meta-train for `formulation` with `seed`, evaluate on `cells`.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorkItem {
    pub formulation: Formulation,
    pub cells: Cells,
    pub seed: u64,
}

impl fmt::Display for WorkItem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let cells = match &self.cells {
            Cells::Condition(name) => name.as_str(),
            Cells::Every => "every condition",
        };
        write!(f, "{} {cells} seed {}", self.formulation.name(), self.seed)
    }
}

impl Experiment {
    /// The work of `formulations` × every evaluation condition × `seeds`, seed by seed, then in
    /// table order (formulation, then condition); under `paper` one item per formulation and seed
    /// (one model serves every condition).
    pub fn work_items(&self, formulations: &[Formulation], seeds: &[u64]) -> Vec<WorkItem> {
        let cells: Vec<Cells> = match self.protocol() {
            Protocol::Paper => vec![Cells::Every],
            Protocol::LeaveConditionOut => self
                .evaluation_conditions()
                .into_iter()
                .map(Cells::Condition)
                .collect(),
        };
        let mut items = Vec::new();
        for &seed in seeds {
            for &formulation in formulations {
                items.extend(cells.iter().map(|cells| WorkItem {
                    formulation,
                    cells: cells.clone(),
                    seed,
                }));
            }
        }
        items
    }

    /// The cells of `item`, in table order.
    pub fn item_cells(&self, item: &WorkItem) -> Result<Vec<Arc<EvaluationCell>>> {
        item_cells(&self.cells, item)
    }

    /// Meta-trains the item's model and evaluates it on its cells (LeARN as a [`Method`], by the
    /// [`Runner`]), telling `progress` of each cell as it ends; results in table order.
    pub fn run_item(&self, item: &WorkItem, progress: &dyn Progress) -> Result<Vec<CellResult>> {
        let train = |cell: &EvaluationCell, seed: u64| {
            self.meta_train(cell.formulation, &cell.condition.name, seed)
        };
        let runner = Runner::new([self as &dyn Method], Some(&train));
        runner
            .run_cells(&self.item_cells(item)?, item.seed, progress)?
            .into_iter()
            .map(|mut outcomes| {
                outcomes.pop().and_then(Outcome::into_learn).ok_or_else(|| {
                    EvaluationError::Mismatch {
                        what: item.to_string(),
                        message: "LeARN gave no cell".to_string(),
                    }
                })
            })
            .collect()
    }

    /// Every item of `items`, in parallel, each item's cells in table order.
    pub fn run_items(
        &self,
        items: &[WorkItem],
        progress: &dyn Progress,
    ) -> Result<Vec<Vec<CellResult>>> {
        items
            .par_iter()
            .map(|item| self.run_item(item, progress))
            .collect()
    }

    /// Every cell of the given formulations (× every evaluation condition), in parallel, returned
    /// in table order; `progress` is told of each cell as it ends. Under `paper` one model per
    /// formulation serves all conditions.
    pub fn run_cells(
        &self,
        formulations: &[Formulation],
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<Vec<CellResult>> {
        let items = self.work_items(formulations, &[seed]);
        Ok(self
            .run_items(&items, progress)?
            .into_iter()
            .flatten()
            .collect())
    }

    /// Generalisation and adaptation MSE of every cell for each seed (the seed-to-seed spread);
    /// `progress` is told of each cell of each seed as it ends.
    pub fn seed_spread(
        &self,
        formulations: &[Formulation],
        seeds: &[u64],
        progress: &dyn Progress,
    ) -> Result<Vec<SpreadCell>> {
        let items = self.work_items(formulations, seeds);
        let summaries: Vec<Vec<CellSummary>> = self
            .run_items(&items, progress)?
            .into_iter()
            .map(|cells| cells.into_iter().map(|c| c.summary).collect())
            .collect();
        Ok(spread_cells(&items, &summaries))
    }
}

/// The seed-to-seed spread of every cell from the summaries of `items` (`summaries[i]` are the
/// cells of `items[i]`): the seeds in their order in `items`, the cells of each seed in item
/// order (table order for [`Experiment::work_items`]).
pub fn spread_cells(items: &[WorkItem], summaries: &[Vec<CellSummary>]) -> Vec<SpreadCell> {
    let mut seeds: Vec<u64> = Vec::new();
    for item in items {
        if !seeds.contains(&item.seed) {
            seeds.push(item.seed);
        }
    }
    let runs: Vec<Vec<&CellSummary>> = seeds
        .iter()
        .map(|&seed| {
            items
                .iter()
                .zip(summaries)
                .filter(|(item, _)| item.seed == seed)
                .flat_map(|(_, cells)| cells)
                .collect()
        })
        .collect();
    let cell_count = runs.iter().map(Vec::len).min().unwrap_or(0);
    (0..cell_count)
        .map(|cell| {
            let first = runs[0][cell];
            SpreadCell {
                formulation: first.formulation,
                condition: first.condition.clone(),
                label: first.label.clone(),
                protocol: first.protocol,
                seeds: seeds.clone(),
                generalisation: Spread::of(runs.iter().map(|r| r[cell].generalisation).collect()),
                adaptation: Spread::of(runs.iter().map(|r| r[cell].adaptation).collect()),
            }
        })
        .collect()
}

/// Statistics of one MSE over seeds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    pub values: Vec<f64>,
    pub mean: f64,
    /// Sample standard deviation (n − 1).
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

impl Spread {
    /// The statistics of `values`.
    pub fn of(values: Vec<f64>) -> Self {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let std = if values.len() > 1 {
            (values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            0.0
        };
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Self {
            values,
            mean,
            std,
            min,
            max,
        }
    }
}

/// The seed-to-seed spread of one table cell.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SpreadCell {
    pub formulation: Formulation,
    pub condition: String,
    pub label: String,
    pub protocol: Protocol,
    pub seeds: Vec<u64>,
    #[serde(rename = "gen_mse")]
    pub generalisation: Spread,
    #[serde(rename = "adapt_mse")]
    pub adaptation: Spread,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(
        formulation: Formulation,
        condition: &str,
        seed: u64,
        generalisation: f64,
    ) -> CellSummary {
        CellSummary {
            formulation,
            condition: condition.to_string(),
            label: condition.to_string(),
            protocol: Protocol::LeaveConditionOut,
            seed,
            adaptation: generalisation / 2.0,
            generalisation,
            unadapted_adaptation: 1.0,
            unadapted_generalisation: 1.0,
            evaluation_file: learn::DataFile {
                path: format!("{condition}.csv").into(),
                sha256: String::new(),
            },
            support_coverage: None,
            query_coverage: None,
        }
    }

    #[test]
    fn the_spread_groups_each_cell_over_the_seeds_whatever_the_order_of_items() {
        let item = |cells: &str, seed| WorkItem {
            formulation: Formulation::Attitude,
            cells: Cells::Condition(cells.to_string()),
            seed,
        };
        let items = [item("a", 1), item("b", 1), item("a", 2), item("b", 2)];
        let summaries: Vec<Vec<CellSummary>> = items
            .iter()
            .map(|i| {
                let Cells::Condition(c) = &i.cells else {
                    unreachable!()
                };
                vec![summary(i.formulation, c, i.seed, i.seed as f64)]
            })
            .collect();
        let spread = spread_cells(&items, &summaries);
        assert_eq!(spread.len(), 2);
        assert_eq!(spread[1].condition, "b");
        assert_eq!(spread[1].seeds, [1, 2]);
        assert_eq!(spread[1].generalisation.values, [1.0, 2.0]);
        assert_eq!(spread[0].adaptation.values, [0.5, 1.0]);
        assert_eq!(items[3].to_string(), "attitude b seed 2");
        let every = WorkItem {
            cells: Cells::Every,
            ..items[0].clone()
        };
        assert_eq!(every.to_string(), "attitude every condition seed 1");
    }
}
