//! `learn meta-train`: meta-train LeARN, adapt online on each evaluation flight, print and save the
//! LeARN columns (and, with `--seed-spread`, the seed-to-seed spread of every cell: see
//! `seed_spread.rs`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use data::ExperimentConditions;
use evaluation::{
    CellSummary, Experiment, Protocol, Segmentation, ShardSpec, evaluation_condition_of,
};
use learn::{Formulation, LearnConfig};
use report::{Method, PublishedTables};
use serde_json::{Value, json};

use output_set::{Existing, FileId, FolderId, OutputSet};

use super::Global;
use super::progress::{Bar, progress_bar};
use super::shard::{SHARD_HELP, parse_shard};

/// What the output manifests record as the writer of the checkpoints and the spread.
pub const PRODUCER: &str = "meta-train";

#[derive(clap::Args, Debug)]
pub struct Args {
    /// LeARN hyper-parameters [default: experiments/learn.json for the flights; with --tasks, the
    /// paper's settings built in, any subset overridden by this file].
    #[arg(long)]
    pub config: Option<PathBuf>,
    #[command(flatten)]
    pub tasks: super::meta_train_tasks::TaskArgs,
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
    /// Override the configuration's seed (a whole number from 0 to 2^64 - 1).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seed)]
    pub seed: Option<u64>,
    /// Summary JSON of the run [default: results/.scratch/learn/learn.json, the tool's scratch,
    /// replaced on every run]; with --tasks, the model (required). A file given here is not
    /// replaced without --force. With --seed-spread --shard K/N: the folder of the shard's result.
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
    #[arg(long, conflicts_with_all = ["condition", "checkpoints", "published", "seed"])]
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
    /// With --seed-spread: run only shard K of N of its work items (K from 0), written to --out
    /// DIR as shard.json; `learn merge` puts the shards together. See docs/cluster.md.
    #[arg(long, value_name = "K/N", value_parser = parse_shard, allow_hyphen_values = true, long_help = SHARD_HELP,
          requires = "seed_spread", requires = "out", conflicts_with = "spread_out")]
    pub shard: Option<ShardSpec>,
}

impl Args {
    /// `--config`, or [`DEFAULT_CONFIG`] for the flights when not given.
    pub fn config_path(&self) -> PathBuf {
        self.config
            .clone()
            .unwrap_or_else(|| PathBuf::from(DEFAULT_CONFIG))
    }

    /// `--out` with `--seed-spread` names the shard's folder, so it needs `--shard`; the message
    /// when it is given without (clap cannot say "conflicts unless").
    pub fn out_without_shard(&self) -> Option<String> {
        (self.seed_spread && self.out.is_some() && self.shard.is_none()).then(|| {
            "the argument '--seed-spread' cannot be used with '--out <OUT>' (the spread goes to \
             --spread-out; --out names a shard's folder, with --shard K/N)"
                .to_string()
        })
    }
}

/// A seed: a whole number from 0 to `u64::MAX`, said so when it is not.
pub(crate) fn parse_seed(text: &str) -> Result<u64, String> {
    text.parse().map_err(|_| {
        format!(
            "a seed is a whole number from 0 to {} (got {text:?})",
            u64::MAX
        )
    })
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

pub fn formulations(names: &[String]) -> anyhow::Result<Vec<Formulation>> {
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

/// Writes `value` as JSON to `staging`, the staging path of `path` (named in errors).
pub fn write_json(staging: &Path, path: &Path, value: &Value) -> anyhow::Result<()> {
    std::fs::write(staging, serde_json::to_string_pretty(value)? + "\n")
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

/// The column of SINDy's generalisation MSE as published (this command does not run SINDy).
const PUBLISHED_SINDY_HEADER: &str = "SINDy gen (paper)";

fn print_cells(cells: &[CellSummary], table: &Option<PublishedTables>) {
    say!(
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
            Some((_, gen_mse)) if cell.generalisation <= gen_mse => "ok",
            Some(_) => "WORSE",
            None => "",
        };
        // Query samples with an input outside the range of the meta-training inputs.
        let outside = cell.query_coverage.as_ref().map_or("-".to_string(), |c| {
            format!("{}/{}", c.samples_outside, c.samples)
        });
        say!(
            "{:<14} {:<10} {:>8.3} {:>8.3} {:>14.3} | {:>15} {:>6} {:<5} | {:>17} | {:>13}",
            cell.formulation.name(),
            cell.label,
            cell.adaptation,
            cell.generalisation,
            cell.unadapted_generalisation,
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

/// The run's output set: the summary (`--out`) and the checkpoints' folder; the inputs, which no
/// output may be.
fn output_set(args: &Args, inputs: &[(String, PathBuf)]) -> anyhow::Result<(OutputSet, Outputs)> {
    let mut set = OutputSet::new(PRODUCER);
    for (what, path) in inputs {
        set.input(format!("the {what} input"), path);
    }
    let force = Existing::from_force(args.force);
    // The defaults are the tool's scratch, replaced on every run.
    let out = match &args.out {
        Some(out) => set.file(out, "--out", force),
        None => set.file(DEFAULT_OUT, "--out", Existing::Replace),
    };
    let checkpoints = match &args.checkpoints {
        Some(dir) => set.folder(dir, "--checkpoints", force),
        None => set.folder(DEFAULT_CHECKPOINTS, "--checkpoints", Existing::Scratch),
    };
    let out_path = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_OUT));
    if super::same_file(&out_path, &checkpoint_dir(args)) {
        anyhow::bail!(
            "{}: is both --out and the --checkpoints directory",
            out_path.display()
        );
    }
    Ok((set, Outputs { out, checkpoints }))
}

/// Where the run writes, in its output set.
#[derive(Clone, Copy)]
struct Outputs {
    out: FileId,
    checkpoints: FolderId,
}

/// `--config` for the flights when not given.
const DEFAULT_CONFIG: &str = "experiments/learn.json";

/// The cells a run meta-trains: every formulation on every evaluated condition, one seed.
struct CellsPlanned<'a> {
    protocol: Protocol,
    formulations: &'a [Formulation],
    evaluated: &'a [String],
    seed: u64,
}

/// Plans every checkpoint in the output set; refuses a checkpoint that is also `--out`.
fn plan_checkpoints(
    set: &mut OutputSet,
    outputs: &Outputs,
    cells: &CellsPlanned,
    out: &Path,
) -> anyhow::Result<()> {
    for &formulation in cells.formulations {
        for condition in cells.evaluated {
            let name = checkpoint_path(
                Path::new(""),
                cells.protocol,
                formulation,
                condition,
                cells.seed,
            );
            let path = set.file_in(outputs.checkpoints, name);
            if super::same_file(&path, out) {
                anyhow::bail!(
                    "{}: is both --out and a checkpoint of this run ({}), refusing to write the summary over it",
                    out.display(),
                    path.display()
                );
            }
        }
    }
    Ok(())
}

/// Meta-trains and adapts every planned cell (only `condition`'s when given), with a bar.
fn train_cells(
    global: &Global,
    experiment: &Experiment,
    cells: &CellsPlanned,
    condition: Option<&str>,
) -> anyhow::Result<Vec<evaluation::CellResult>> {
    let started = Instant::now();
    let bar = Bar(progress_bar(
        global.show_progress(),
        cells.formulations.len() * cells.evaluated.len(),
        "meta-train",
    ));
    let results = match condition {
        Some(condition) => cells
            .formulations
            .iter()
            .map(|&f| {
                let cell = experiment.run_cell(f, condition, cells.seed);
                bar.0.inc(1);
                cell
            })
            .collect::<evaluation::Result<Vec<_>>>(),
        None => experiment.run_cells(cells.formulations, cells.seed, &bar),
    };
    bar.0.finish_and_clear();
    let results = results?;
    let elapsed = started.elapsed().as_secs_f64();
    say!(
        "meta-training and adaptation of {} cells: {elapsed:.1} s",
        results.len()
    );
    Ok(results)
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if args.tasks.tasks.is_some() {
        return super::meta_train_tasks::run(global, &args);
    }
    args.tasks.refuse_without_tasks()?;
    let config_path = args.config_path();
    let published_path = args
        .published
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_PUBLISHED));
    let inputs: Vec<(String, PathBuf)> = [
        ("--config", &config_path),
        ("--conditions", &args.conditions),
        ("--published", &published_path),
    ]
    .map(|(what, path)| (what.to_string(), path.clone()))
    .into();
    if args.seed_spread {
        return super::seed_spread::run(global, &args, &inputs);
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_OUT));
    let checkpoint_dir = checkpoint_dir(&args);
    let (mut set, outputs) = output_set(&args, &inputs)?;
    set.check()?;
    let mut config = LearnConfig::load(&config_path)?;
    if let Some(seed) = args.seed {
        config = config.with_seed(seed);
    }
    let table = published_tables(args.published.as_deref())?;
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

    let seed = config.get().seed;
    let cells_planned = CellsPlanned {
        protocol,
        formulations: &formulations,
        evaluated: &evaluated,
        seed,
    };
    plan_checkpoints(&mut set, &outputs, &cells_planned, &out)?;
    // Every output is proven writable (and its folder locked) before any training.
    let staged = set.prepare()?;
    // The paper's segments (halves, forward differences): `learn reproduce` takes others from its
    // run configuration.
    let experiment = Experiment::load(
        config.clone(),
        conditions,
        &data_dir,
        Some(protocol),
        Segmentation::PAPER,
    )?;
    say!("protocol: {}", protocol.name());

    let cells = train_cells(
        global,
        &experiment,
        &cells_planned,
        args.condition.as_deref(),
    )?;
    let Outputs {
        out: out_file,
        checkpoints: checkpoint_folder,
    } = outputs;
    let mut checkpoints = Vec::new();
    for cell in &cells {
        let at = |dir: &Path| {
            checkpoint_path(
                dir,
                protocol,
                cell.summary.formulation,
                &cell.summary.condition,
                seed,
            )
        };
        super::staged_write(&staged, || {
            cell.model.save(&at(staged.dir(checkpoint_folder)))
        })?;
        checkpoints.push(at(&checkpoint_dir));
    }
    let summaries: Vec<CellSummary> = cells.iter().map(|c| c.summary.clone()).collect();
    write_json(
        staged.path(out_file),
        &out,
        &json!({
            "protocol": protocol.name(),
            "seed": seed,
            "config": config.get(),
            "cells": summaries,
            "checkpoints": checkpoints,
        }),
    )?;
    staged.commit()?;
    print_cells(&summaries, &table);
    say!(
        "wrote {} and {} checkpoints under {}",
        out.display(),
        checkpoints.len(),
        checkpoint_dir.display()
    );
    Ok(())
}
