//! Scratch tuning aid (not used by the pipeline): meta-trains every cell once with a configuration,
//! then reports adaptation / generalisation MSE for a grid of online-adaptation settings, so that
//! the settings in `experiments/learn.json` can be chosen on measured numbers.
//!
//! cargo run -p learn --example tune_adaptation -- CONFIG [SEED]

use std::path::Path;

use data::{ExperimentConditions, FlightLog, Formulation};
use learn::{
    AdaptationConfig, Experiment, LearnConfig, adapt_online, flight_segments, mean_squared_error,
    segment_batch,
};
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let arguments: Vec<String> = std::env::args().skip(1).collect();
    let config = LearnConfig::load(Path::new(&arguments[0]))?;
    let seed: u64 = arguments
        .get(1)
        .map_or(Ok(config.get().seed), |s| s.parse())?;
    let conditions = ExperimentConditions::load(Path::new("experiments/conditions.json"))?;
    let data_dir = data::resolve_data_dir(None)?;
    let experiment = Experiment::load(config.clone(), conditions.clone(), &data_dir, None)?;
    let started = std::time::Instant::now();
    let formulations: Vec<Formulation> = match std::env::var("TUNE_FORMULATION") {
        Ok(name) => vec![Formulation::parse(&name)?],
        Err(_) => Formulation::ALL.to_vec(),
    };
    let cells = experiment.run_cells(&formulations, seed)?;
    for cell in &cells {
        eprintln!(
            "{} {}: unadapted gen {:.3}, meta-loss first/last {:.3}/{:.3}",
            cell.summary.formulation.name(),
            cell.summary.label,
            cell.summary.unadapted_gen_mse,
            cell.model.meta_loss_history[0],
            cell.model
                .meta_loss_history
                .iter()
                .rev()
                .take(20)
                .sum::<f64>()
                / 20.0
        );
    }
    eprintln!(
        "meta-training + default adaptation: {:.1} s",
        started.elapsed().as_secs_f64()
    );
    let base = config.get().adaptation.clone();
    let mut grid = Vec::new();
    for step in [0.0003, 0.0005] {
        for passes in [3, 5] {
            for window in [1] {
                if step == 0.0 && passes > 3 {
                    continue;
                }
                grid.push(AdaptationConfig {
                    step,
                    passes,
                    window,
                    ..base.clone()
                });
            }
        }
    }
    let rows: Vec<String> = grid
        .par_iter()
        .map(|adaptation| {
            let mut line = format!(
                "step {:<6} passes {} window {:<2}:",
                adaptation.step, adaptation.passes, adaptation.window
            );
            let mut total = 0.0;
            for cell in &cells {
                let condition = conditions.condition(&cell.summary.condition).unwrap();
                let path =
                    conditions.flight_path(&data_dir, condition, &conditions.evaluation_controller);
                let log = FlightLog::read(&path).unwrap();
                let model = &cell.model;
                let (support, query) = flight_segments(&log, model.formulation).unwrap();
                let (support, query) = (segment_batch(&support), segment_batch(&query));
                let s_in = model.standardiser.apply(&support.inputs);
                let q_in = model.standardiser.apply(&query.inputs);
                let adapted = adapt_online(
                    &model.architecture,
                    &model.parameters,
                    &s_in,
                    &support.targets,
                    adaptation,
                );
                let gen_mse = mean_squared_error(
                    &model.architecture.predict(&adapted, &q_in),
                    &query.targets,
                );
                total += gen_mse;
                line.push_str(&format!(" {gen_mse:.3}"));
            }
            line.push_str(&format!(" | mean {:.4}", total / cells.len() as f64));
            line
        })
        .collect();
    for cell in &cells {
        eprint!(
            "{}/{} ",
            cell.summary.formulation.name(),
            cell.summary.label
        );
    }
    eprintln!();
    for row in rows {
        println!("{row}");
    }
    Ok(())
}
