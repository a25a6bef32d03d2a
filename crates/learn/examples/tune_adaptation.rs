//! Tuning aid (not used by the pipeline): reports the generalisation MSE of every cell for a grid of
//! online-adaptation settings, starting from the checkpoints `learn meta-train` wrote, so that the
//! adaptation settings of `experiments/learn.json` are chosen on measured numbers. It only reads
//! the support segment to adapt and the query segment to score.
//!
//! cargo run -p learn --example tune_adaptation -- CHECKPOINT_DIR

use std::path::Path;

use data::{ExperimentConditions, FlightLog};
use learn::{
    AdaptationConfig, MetaTrainedModel, adapt_online, flight_segments, mean_squared_error,
    segment_batch,
};
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let directory = std::env::args()
        .nth(1)
        .ok_or("usage: tune_adaptation CHECKPOINT_DIR")?;
    let conditions = ExperimentConditions::load(Path::new("experiments/conditions.json"))?;
    let data_dir = data::resolve_data_dir(None)?;
    let mut paths: Vec<_> = std::fs::read_dir(&directory)?
        .map(|entry| entry.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    paths.sort();
    let mut cells = Vec::new();
    for path in paths {
        let model = MetaTrainedModel::load(&path)?;
        let held_out = model
            .held_out_condition
            .clone()
            .ok_or("no held-out condition")?;
        let condition = conditions.condition(&held_out)?;
        let flight =
            conditions.flight_path(&data_dir, condition, &conditions.evaluation_controller);
        let log = FlightLog::read(&flight)?;
        let (support, query) = flight_segments(&log, model.formulation)?;
        eprint!("{}/{} ", model.formulation.name(), condition.label());
        cells.push((model, segment_batch(&support), segment_batch(&query)));
    }
    eprintln!();
    let base = cells[0].0.config.adaptation.clone();
    let mut grid = Vec::new();
    for step in [0.0003, 0.0005, 0.001] {
        for passes in [3, 5, 8] {
            for (lipschitz_weight, lipschitz_bound) in [(0.0, 0.0), (0.01, 1.0), (0.05, 0.5)] {
                grid.push(AdaptationConfig {
                    step,
                    passes,
                    lipschitz_weight,
                    lipschitz_bound,
                    ..base.clone()
                });
            }
        }
    }
    let rows: Vec<String> = grid
        .par_iter()
        .map(|adaptation| {
            let mut line = format!(
                "step {:<6} passes {} λ {:<4} L {:<3}:",
                adaptation.step,
                adaptation.passes,
                adaptation.lipschitz_weight,
                adaptation.lipschitz_bound
            );
            let mut total = 0.0;
            for (model, support, query) in &cells {
                let support_inputs = model.standardiser.apply(&support.inputs);
                let query_inputs = model.standardiser.apply(&query.inputs);
                let adapted = adapt_online(
                    &model.architecture,
                    &model.parameters,
                    &support_inputs,
                    &support.targets,
                    adaptation,
                );
                let predictions = model.architecture.predict(&adapted, &query_inputs);
                let gen_mse = mean_squared_error(&predictions, &query.targets);
                total += gen_mse;
                line.push_str(&format!(" {gen_mse:.3}"));
            }
            line.push_str(&format!(" | mean {:.4}", total / cells.len() as f64));
            line
        })
        .collect();
    for row in rows {
        println!("{row}");
    }
    Ok(())
}
