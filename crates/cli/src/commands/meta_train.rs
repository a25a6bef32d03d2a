//! `learn meta-train`: meta-train LeARN, adapt online on each evaluation flight, print and save the
//! LeARN columns (and, with `--seed-spread`, the seed-to-seed spread of every cell).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use data::{ExperimentConditions, Formulation};
use indicatif::{ProgressBar, ProgressStyle};
use learn::{CellSummary, Experiment, LearnConfig, Protocol, evaluation_condition_of};
use report::{Method, PublishedTables};
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
    /// Only this evaluation condition (name or label; role "evaluation" in --conditions); default
    /// all.
    #[arg(long)]
    pub condition: Option<String>,
    /// Override the configuration's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Summary JSON of the run [default: results/.scratch/learn/learn.json, the tool's scratch,
    /// replaced on every run]. A file given here is not replaced without --force.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Directory of the JSON checkpoints, one per formulation and fold [default:
    /// results/.scratch/learn/checkpoints, replaced on every run]. A checkpoint already in a
    /// directory given here is not replaced without --force.
    #[arg(long)]
    pub checkpoints: Option<PathBuf>,
    /// The published numbers to compare with [default: paper/published.json, skipped when
    /// absent]. A file given here must exist.
    #[arg(long)]
    pub published: Option<PathBuf>,
    /// Rerun every cell with each of the configuration's `spread_seeds` and write the spread
    /// (every condition: the spread is what the tolerances of paper/tolerances.json come from) to
    /// `--spread-out` only: no summary (`--out`), no checkpoints (`--checkpoints`), no
    /// comparison with the published numbers (`--published`), and the seeds are the
    /// configuration's `spread_seeds` (not `--seed`).
    #[arg(long, conflicts_with_all = ["condition", "out", "checkpoints", "published", "seed"])]
    pub seed_spread: bool,
    /// Where `--seed-spread` writes its result (only with `--seed-spread`).
    #[arg(
        long,
        default_value = "experiments/learn-seed-spread.json",
        requires = "seed_spread"
    )]
    pub spread_out: PathBuf,
    /// Replace an existing `--spread-out` or `--out` file, or checkpoints in `--checkpoints`.
    /// No output may be one of the input files (--config, --conditions, --published), even
    /// with --force.
    #[arg(long)]
    pub force: bool,
}

/// `--out` when not given: the tool's own scratch, replaced on every run.
const DEFAULT_OUT: &str = "results/.scratch/learn/learn.json";
/// `--checkpoints` when not given: the tool's own scratch, replaced on every run.
const DEFAULT_CHECKPOINTS: &str = "results/.scratch/learn/checkpoints";
/// `--published` when not given (skipped when absent).
const DEFAULT_PUBLISHED: &str = "paper/published.json";

/// The published tables: from a file given with --published (which must exist and parse), or from
/// the default file when present (which must then parse).
fn published_tables(path: Option<&Path>) -> anyhow::Result<Option<PublishedTables>> {
    let (path, explicit) = match path {
        Some(path) => (path, true),
        None => (Path::new(DEFAULT_PUBLISHED), false),
    };
    if !explicit && !path.exists() {
        return Ok(None);
    }
    Ok(Some(PublishedTables::load(path)?))
}

fn formulations(names: &[String]) -> anyhow::Result<Vec<Formulation>> {
    if names.is_empty() {
        return Ok(Formulation::ALL.to_vec());
    }
    let mut formulations = Vec::new();
    for name in names {
        let formulation = Formulation::parse(name)?;
        if formulations.contains(&formulation) {
            anyhow::bail!("--formulation {name}: given twice");
        }
        formulations.push(formulation);
    }
    Ok(formulations)
}

fn write_json(path: &Path, value: &Value) -> anyhow::Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
    }
    std::fs::write(path, serde_json::to_string_pretty(value)? + "\n")
        .with_context(|| path.display().to_string())
}

/// The published (adapt, gen) of `method` for a cell, if the file has it.
fn published(
    table: &Option<PublishedTables>,
    cell: &CellSummary,
    method: Method,
) -> Option<(f64, f64)> {
    let mse = table
        .as_ref()?
        .get(cell.formulation.name(), &cell.label)?
        .get(method);
    Some((mse.adaptation, mse.generalisation))
}

/// A bar over `cells` cells on standard error, drawn only when `show` (a terminal, not --quiet), in
/// the style of `learn reproduce`.
fn progress_bar(show: bool, cells: usize, message: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(cells as u64).with_message(message.to_string());
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:32}] {pos}/{len} cells, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    // Drawn (and its clock kept running) from the start: the first cells take seconds.
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// The column of SINDy's generalisation MSE as published (this command does not run SINDy).
const PUBLISHED_SINDY_HEADER: &str = "SINDy gen (paper)";

fn print_cells(cells: &[CellSummary], table: &Option<PublishedTables>) {
    println!(
        "{:<14} {:<10} {:>8} {:>8} {:>10} | {:>15} {:>12} | {:>17} | {:>13}",
        "formulation",
        "condition",
        "adapt",
        "gen",
        "gen(unadapted)",
        "published adapt",
        "gen",
        PUBLISHED_SINDY_HEADER,
        "query outside"
    );
    for cell in cells {
        let learn = published(table, cell, Method::Learn);
        let sindy = published(table, cell, Method::Sindy);
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
            "{:<14} {:<10} {:>8.3} {:>8.3} {:>14.3} | {:>15} {:>6} {:<5} | {:>17} | {:>13}",
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

/// The checkpoint of one cell under `dir`.
fn checkpoint_path(
    dir: &Path,
    protocol: Protocol,
    formulation: Formulation,
    condition: &str,
    seed: u64,
) -> PathBuf {
    dir.join(format!(
        "{}-{}-{condition}-seed{seed}.json",
        protocol.name(),
        formulation.name(),
    ))
}

/// The directory of the checkpoints (`--checkpoints` or its default).
fn checkpoint_dir(args: &Args) -> PathBuf {
    args.checkpoints
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_CHECKPOINTS))
}

/// Every checkpoint this run writes, checked before any work: never `--out` nor an input (whatever
/// the spelling of either path), a place a file can be written, not an existing file in a
/// directory given with --checkpoints unless --force.
fn check_checkpoints(
    args: &Args,
    protocol: Protocol,
    formulations: &[Formulation],
    evaluated: &[String],
    seed: u64,
    out: &Path,
    inputs: &[(&str, &Path)],
) -> anyhow::Result<()> {
    let dir = checkpoint_dir(args);
    if super::same_file(out, &dir) {
        anyhow::bail!(
            "{}: is both --out and the --checkpoints directory",
            out.display()
        );
    }
    for &formulation in formulations {
        for condition in evaluated {
            let path = checkpoint_path(&dir, protocol, formulation, condition, seed);
            if super::same_file(&path, out) {
                anyhow::bail!(
                    "{}: is both --out and a checkpoint of this run ({}), refusing to write the summary over it",
                    out.display(),
                    path.display()
                );
            }
            super::refuse_input_as_output(&path, inputs)?;
            super::refuse_unwritable_file(&path, "--checkpoints")?;
            if args.checkpoints.is_some() {
                super::refuse_overwrite(&path, args.force)?;
            }
        }
    }
    Ok(())
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let published_path = args
        .published
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_PUBLISHED));
    let inputs: [(&str, &Path); 3] = [
        ("--config", &args.config),
        ("--conditions", &args.conditions),
        ("--published", &published_path),
    ];
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_OUT));
    let checkpoint_dir = checkpoint_dir(&args);
    if args.seed_spread {
        super::check_output(&args.spread_out, "--spread-out", args.force, &inputs)?;
    } else {
        super::refuse_input_as_output(&out, &inputs)?;
        super::refuse_unwritable_file(&out, "--out")?;
        if args.out.is_some() {
            super::refuse_overwrite(&out, args.force)?;
        }
        super::refuse_unwritable_dir(&checkpoint_dir, "--checkpoints")?;
    }
    let mut config = LearnConfig::load(&args.config)?;
    if let Some(seed) = args.seed {
        config = config.with_seed(seed);
    }
    // The spread is not compared with the paper: no published file is read for it.
    let table = if args.seed_spread {
        None
    } else {
        published_tables(args.published.as_deref())?
    };
    let conditions = ExperimentConditions::load(&args.conditions)?;
    let data_dir = global.data_dir()?;
    let protocol = Protocol::parse(&args.protocol)?;
    let formulations = formulations(&args.formulations)?;
    let evaluated: Vec<String> = match &args.condition {
        Some(condition) => vec![
            evaluation_condition_of(&conditions, condition)
                .with_context(|| format!("--condition {condition}"))?
                .name
                .clone(),
        ],
        None => conditions.evaluation().map(|c| c.name.clone()).collect(),
    };
    let protocol = Protocol::resolve(protocol, &conditions, &data_dir);

    if !args.seed_spread {
        let seed = config.get().seed;
        check_checkpoints(
            &args,
            protocol,
            &formulations,
            &evaluated,
            seed,
            &out,
            &inputs,
        )?;
    }
    let experiment = Experiment::load(config.clone(), conditions, &data_dir, Some(protocol))?;
    println!("protocol: {}", protocol.name());

    if args.seed_spread {
        let seeds = config.get().spread_seeds.clone();
        let started = Instant::now();
        let cells = formulations.len() * experiment.evaluation_conditions().len() * seeds.len();
        let bar = progress_bar(global.show_progress(), cells, "seed spread");
        let spread = experiment.seed_spread_observed(&formulations, &seeds, &|_| bar.inc(1));
        bar.finish_and_clear();
        let spread = spread?;
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
    let bar = progress_bar(
        global.show_progress(),
        formulations.len() * evaluated.len(),
        "meta-train",
    );
    let cells = match &args.condition {
        Some(condition) => formulations
            .iter()
            .map(|&f| {
                let cell = experiment.run_cell(f, condition, seed);
                bar.inc(1);
                cell
            })
            .collect::<learn::Result<Vec<_>>>(),
        None => experiment.run_cells_observed(&formulations, seed, &|_| bar.inc(1)),
    };
    bar.finish_and_clear();
    let cells = cells?;
    let elapsed = started.elapsed().as_secs_f64();
    println!(
        "meta-training and adaptation of {} cells: {elapsed:.1} s",
        cells.len()
    );
    let mut checkpoints = Vec::new();
    for cell in &cells {
        let path = checkpoint_path(
            &checkpoint_dir,
            protocol,
            cell.summary.formulation,
            &cell.summary.condition,
            seed,
        );
        cell.model.save(&path)?;
        checkpoints.push(path);
    }
    let summaries: Vec<CellSummary> = cells.iter().map(|c| c.summary.clone()).collect();
    print_cells(&summaries, &table);
    write_json(
        &out,
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
        out.display(),
        checkpoints.len(),
        checkpoint_dir.display()
    );
    Ok(())
}
