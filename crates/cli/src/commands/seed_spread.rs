//! `learn meta-train --seed-spread`: every cell meta-trained and adapted once per seed of the
//! configuration's `spread_seeds`, the spread written to `--spread-out`; with `--shard K/N --out
//! DIR`, one shard of that work (merged by `learn merge`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;

use data::ExperimentConditions;
use evaluation::{
    Experiment, Protocol, Segmentation, ShardProvenance, ShardSpec, SpreadCell, StageTiming,
};
use learn::LearnConfig;
use output_set::{Existing, OutputSet, Staged};

use super::Global;
use super::meta_train::{Args, PRODUCER, formulations};
use super::progress::{Bar, progress_bar};
use super::shard::ShardOutputs;

/// The writer of a shard's result (never removes, nor is removed by, the run's own files).
const SHARD_PRODUCER: &str = "seed-spread-shard";

/// Where the spread goes: the spread file, or a shard's folder.
enum Destination {
    File(OutputSet, output_set::FileId),
    Shard(ShardOutputs, ShardSpec),
}

/// A destination prepared before any training.
enum Prepared {
    File(Staged, output_set::FileId),
    Shard(super::shard::StagedShard, ShardSpec),
}

pub fn run(global: &Global, args: &Args, inputs: &[(String, PathBuf)]) -> anyhow::Result<()> {
    let destination = match (args.shard, &args.out) {
        (Some(shard), Some(out)) => Destination::Shard(
            ShardOutputs::plan(SHARD_PRODUCER, out, args.force, inputs)?,
            shard,
        ),
        _ => {
            let mut set = OutputSet::new(PRODUCER);
            for (what, path) in inputs {
                set.input(format!("the {what} input"), path);
            }
            let file = set.file(
                &args.spread_out,
                "--spread-out",
                Existing::from_force(args.force),
            );
            set.check()?;
            Destination::File(set, file)
        }
    };
    let config = LearnConfig::load(&args.config_path())?;
    let conditions = ExperimentConditions::load(&args.conditions)?;
    let data_dir = global.data_dir()?;
    let protocol = Protocol::parse(&args.protocol)?;
    let formulations = formulations(&args.formulations)?;
    let protocol = Protocol::resolve(protocol, &conditions, &data_dir);
    // Every output is proven writable (and its folder locked) before any training.
    let prepared = match destination {
        Destination::File(set, file) => Prepared::File(set.prepare()?, file),
        Destination::Shard(outputs, shard) => Prepared::Shard(outputs.prepare()?, shard),
    };
    let started = Instant::now();
    let experiment = Experiment::load(
        config,
        conditions,
        &data_dir,
        Some(protocol),
        Segmentation::PAPER,
    )?;
    let loaded = started.elapsed().as_secs_f64();
    say!("protocol: {}", protocol.name());
    let sweep = evaluation::spread_sweep(
        &experiment,
        &formulations,
        &args.config_path(),
        &[&args.config_path(), &args.conditions],
    )?;
    let shard = match &prepared {
        Prepared::File(..) => ShardSpec::WHOLE,
        Prepared::Shard(_, shard) => *shard,
    };
    let cells = shard_cells(
        &sweep.items,
        shard,
        experiment.evaluation_conditions().len(),
    );
    let bar = Bar(progress_bar(global.show_progress(), cells, "seed spread"));
    let results = evaluation::run_spread(&experiment, &sweep, shard, &bar);
    bar.0.finish_and_clear();
    let results = results?;
    match prepared {
        Prepared::Shard(staged, shard) => {
            let stages = vec![
                stage("load flights", loaded),
                stage("seed spread", started.elapsed().as_secs_f64() - loaded),
            ];
            let provenance = ShardProvenance::here(Path::new("."), stages);
            staged.commit(&sweep.shard_file(shard, results, provenance)?)
        }
        Prepared::File(staged, file) => {
            let summaries: Vec<_> = results.into_iter().map(|r| r.result).collect();
            let document = evaluation::spread_document(&sweep.context, &sweep.items, &summaries);
            let took = format!("{:.1} s", started.elapsed().as_secs_f64());
            print_spread(&document.cells, &sweep.context.seeds, &took);
            write_spread(staged.path(file), &args.spread_out, &document)?;
            staged.commit()?;
            say!("wrote {}", args.spread_out.display());
            Ok(())
        }
    }
}

/// Writes the spread file `document` to `staging` (the output `path`, which errors name).
pub fn write_spread(
    staging: &Path,
    path: &Path,
    document: &evaluation::SpreadDocument,
) -> anyhow::Result<()> {
    std::fs::write(staging, document.to_json()).with_context(|| path.display().to_string())
}

fn stage(name: &str, seconds: f64) -> StageTiming {
    StageTiming {
        stage: name.to_string(),
        seconds,
    }
}

/// How many cells the items of `shard` evaluate.
fn shard_cells(items: &[evaluation::WorkItem], shard: ShardSpec, conditions: usize) -> usize {
    shard
        .positions(items.len())
        .iter()
        .map(|&p| match items[p].cells {
            evaluation::Cells::Condition(_) => 1,
            evaluation::Cells::Every => conditions,
        })
        .sum()
}

/// The spread table on standard output; `took` says how it was made (a time, or a merge).
pub fn print_spread(spread: &[SpreadCell], seeds: &[u64], took: &str) {
    say!("seed spread over seeds {seeds:?} ({took})");
    say!(
        "{:<14} {:<10} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "formulation",
        "condition",
        "gen mean",
        "gen std",
        "gen min",
        "gen max",
        "adapt std"
    );
    for cell in spread {
        say!(
            "{:<14} {:<10} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
            cell.formulation.name(),
            cell.label,
            cell.generalisation.mean,
            cell.generalisation.std,
            cell.generalisation.min,
            cell.generalisation.max,
            cell.adaptation.std
        );
    }
}
