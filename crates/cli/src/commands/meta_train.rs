//! `learn meta-train`: meta-train LeARN, adapt online on each evaluation flight, print and save the
//! LeARN columns (and, with `--seed-spread`, the seed-to-seed spread of every cell).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use data::{ExperimentConditions, Formulation};
use learn::{CellSummary, Experiment, LearnConfig, Protocol};
use serde_json::{Value, json};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// LeARN hyper-parameters.
    #[arg(long, default_value = "experiments/learn.json")]
    pub config: PathBuf,
    /// Wind conditions and flight files.
    #[arg(long, default_value = "experiments/conditions.json")]
    pub conditions: PathBuf,
    /// `paper`, `leave-condition-out`, or `auto` (paper when its flights are present).
    #[arg(long, default_value = "auto")]
    pub protocol: String,
    /// Formulations to run (translational, attitude, full); default all three.
    #[arg(long = "formulation")]
    pub formulations: Vec<String>,
    /// Only this evaluation condition (name or label); default all.
    #[arg(long)]
    pub condition: Option<String>,
    /// Override the configuration's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Summary JSON of the run.
    #[arg(long, default_value = "results/.scratch/learn/learn.json")]
    pub out: PathBuf,
    /// Directory of the JSON checkpoints (one per formulation and fold).
    #[arg(long, default_value = "results/.scratch/learn/checkpoints")]
    pub checkpoints: PathBuf,
    /// The published numbers to compare with.
    #[arg(long, default_value = "paper/published.json")]
    pub published: PathBuf,
    /// Rerun every cell with each of the configuration's `spread_seeds` and write the spread
    /// (every condition: the spread is what the tolerances of paper/tolerances.json come from).
    #[arg(long, conflicts_with = "condition")]
    pub seed_spread: bool,
    /// Where `--seed-spread` writes its result.
    #[arg(long, default_value = "experiments/learn-seed-spread.json")]
    pub spread_out: PathBuf,
    /// Replace an existing `--spread-out` file.
    #[arg(long)]
    pub force: bool,
}

fn formulations(names: &[String]) -> anyhow::Result<Vec<Formulation>> {
    if names.is_empty() {
        return Ok(Formulation::ALL.to_vec());
    }
    names
        .iter()
        .map(|n| Formulation::parse(n).map_err(Into::into))
        .collect()
}

fn write_json(path: &Path, value: &Value) -> anyhow::Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
    }
    std::fs::write(path, serde_json::to_string_pretty(value)? + "\n")
        .with_context(|| path.display().to_string())
}

/// The published (adapt, gen) of `method` (`learn` or `sindy`) for a cell, if the file has it.
fn published(table: &Option<Value>, cell: &CellSummary, method: &str) -> Option<(f64, f64)> {
    let entry = table.as_ref()?["tables"][cell.formulation.name()][&cell.label][method].clone();
    Some((entry["adapt"].as_f64()?, entry["gen"].as_f64()?))
}

fn print_cells(cells: &[CellSummary], table: &Option<Value>) {
    println!(
        "{:<14} {:<10} {:>8} {:>8} {:>10} | {:>15} {:>12} | {:>9} | {:>13}",
        "formulation",
        "condition",
        "adapt",
        "gen",
        "gen(unadapted)",
        "published adapt",
        "gen",
        "SINDy gen",
        "query outside"
    );
    for cell in cells {
        let learn = published(table, cell, "learn");
        let sindy = published(table, cell, "sindy");
        let show = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
        let verdict = match learn {
            Some((_, gen_mse)) if cell.gen_mse <= gen_mse => "ok",
            Some(_) => "WORSE",
            None => "",
        };
        // Query samples with an input outside the range of the meta-training inputs.
        let outside = cell.query_coverage.as_ref().map_or("-".to_string(), |c| {
            format!("{}/{}", c.samples_outside, c.samples)
        });
        println!(
            "{:<14} {:<10} {:>8.3} {:>8.3} {:>14.3} | {:>15} {:>6} {:<5} | {:>9} | {:>13}",
            cell.formulation.name(),
            cell.label,
            cell.adapt_mse,
            cell.gen_mse,
            cell.unadapted_gen_mse,
            show(learn.map(|l| l.0)),
            show(learn.map(|l| l.1)),
            verdict,
            show(sindy.map(|s| s.1)),
            outside,
        );
    }
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if args.seed_spread {
        super::refuse_overwrite(&args.spread_out, args.force)?;
    }
    let mut config = LearnConfig::load(&args.config)?;
    if let Some(seed) = args.seed {
        config = config.with_seed(seed);
    }
    let conditions = ExperimentConditions::load(&args.conditions)?;
    let data_dir = global.data_dir()?;
    let protocol = Protocol::parse(&args.protocol)?;
    let formulations = formulations(&args.formulations)?;
    let table = std::fs::read_to_string(&args.published)
        .ok()
        .and_then(|text| serde_json::from_str::<Value>(&text).ok());
    let experiment = Experiment::load(config.clone(), conditions, &data_dir, protocol)?;
    let protocol = experiment.protocol();
    println!("protocol: {}", protocol.name());

    if args.seed_spread {
        let seeds = config.get().spread_seeds.clone();
        let started = Instant::now();
        let spread = experiment.seed_spread(&formulations, &seeds)?;
        println!(
            "seed spread over seeds {seeds:?} ({:.1} s)",
            started.elapsed().as_secs_f64()
        );
        println!(
            "{:<14} {:<10} {:>9} {:>9} {:>9} {:>9} {:>9}",
            "formulation", "condition", "gen mean", "gen std", "gen min", "gen max", "adapt std"
        );
        for cell in &spread {
            println!(
                "{:<14} {:<10} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
                cell.formulation.name(),
                cell.label,
                cell.gen_mse.mean,
                cell.gen_mse.std,
                cell.gen_mse.min,
                cell.gen_mse.max,
                cell.adapt_mse.std
            );
        }
        write_json(
            &args.spread_out,
            &json!({
                "what": "seed-to-seed spread of the LeARN adaptation and generalisation MSE per table cell",
                "how": format!(
                    "learn meta-train --seed-spread --config {} (every cell meta-trained and adapted once per seed; std is the sample standard deviation over seeds)",
                    args.config.display()
                ),
                "protocol": protocol.name(),
                "config": config.get(),
                "seeds": seeds,
                "cells": spread,
            }),
        )?;
        println!("wrote {}", args.spread_out.display());
        return Ok(());
    }

    let seed = config.get().seed;
    let started = Instant::now();
    let cells = match &args.condition {
        Some(condition) => formulations
            .iter()
            .map(|&f| experiment.run_cell(f, condition, seed))
            .collect::<learn::Result<Vec<_>>>()?,
        None => experiment.run_cells(&formulations, seed)?,
    };
    let elapsed = started.elapsed().as_secs_f64();
    println!(
        "meta-training and adaptation of {} cells: {elapsed:.1} s",
        cells.len()
    );
    let mut checkpoints = Vec::new();
    for cell in &cells {
        let name = format!(
            "{}-{}-{}-seed{}.json",
            protocol.name(),
            cell.summary.formulation.name(),
            cell.summary.condition,
            seed
        );
        let path = args.checkpoints.join(name);
        cell.model.save(&path)?;
        checkpoints.push(path);
    }
    let summaries: Vec<CellSummary> = cells.iter().map(|c| c.summary.clone()).collect();
    print_cells(&summaries, &table);
    write_json(
        &args.out,
        &json!({
            "protocol": protocol.name(),
            "seed": seed,
            "config": config.get(),
            "cells": summaries,
            "checkpoints": checkpoints,
        }),
    )?;
    println!(
        "wrote {} and {} checkpoints under {}",
        args.out.display(),
        checkpoints.len(),
        args.checkpoints.display()
    );
    Ok(())
}
