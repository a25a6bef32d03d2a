//! `learn merge`: the shards of one sweep (`learn reproduce`, `learn ablations` or `learn
//! meta-train --seed-spread` with `--shard K/N`) checked and put together, written exactly as the
//! unsharded command writes them, through the same code.

use std::path::PathBuf;
use std::time::Instant;

use evaluation::{ShardDocument, SweepKind};
use output_set::{Existing, OutputSet};
use serde::Serialize;
use serde::de::DeserializeOwned;

use super::Global;
use super::reproduce::Destinations;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Where the merged result goes, as the unsharded command's option: reproduce's and
    /// ablations' --out folder, the seed spread's --spread-out file.
    #[arg(long)]
    pub out: PathBuf,
    /// Reproduce shards only: where the LaTeX tables go [default: paper/tables].
    #[arg(long)]
    pub latex_dir: Option<PathBuf>,
    /// Reproduce shards only: also rewrite the generated results block of this README.
    #[arg(long)]
    pub readme: Option<PathBuf>,
    /// Replace the files an earlier run of the same command wrote (files it did not write are
    /// never replaced).
    #[arg(long)]
    pub force: bool,
    /// The shards' folders (each holding the shard.json that `--shard K/N --out DIR` wrote).
    #[arg(required = true, value_name = "SHARD_DIR")]
    pub shards: Vec<PathBuf>,
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let documents = args
        .shards
        .iter()
        .map(|dir| evaluation::read_shard(dir))
        .collect::<evaluation::Result<Vec<ShardDocument>>>()?;
    let kind = one_kind(&documents)?;
    if kind != SweepKind::Reproduce
        && let Some(option) = [("--latex-dir", &args.latex_dir), ("--readme", &args.readme)]
            .iter()
            .find_map(|(option, value)| value.as_ref().map(|_| option))
    {
        anyhow::bail!(
            "{option} applies to reproduce shards only; these are shards of {}",
            kind.command()
        );
    }
    let inputs: Vec<(String, PathBuf)> = documents
        .iter()
        .map(|d| ("shard".to_string(), d.path.clone()))
        .collect();
    match kind {
        SweepKind::Reproduce => merge_reproduce(&args, documents, &inputs, start),
        SweepKind::Ablations => merge_ablations(&args, documents, &inputs, start),
        SweepKind::SeedSpread => merge_spread(&args, documents, &inputs),
    }
}

/// The kind every shard has; an error naming the first that differs.
fn one_kind(documents: &[ShardDocument]) -> anyhow::Result<SweepKind> {
    let first = &documents[0];
    if let Some(other) = documents.iter().find(|d| d.kind != first.kind) {
        anyhow::bail!(
            "{}: kind: a shard of {}, {} of {}",
            other.path.display(),
            other.kind.command(),
            first.path.display(),
            first.kind.command()
        );
    }
    Ok(first.kind)
}

/// The shards read as one sweep's, checked and merged.
fn merged<C, R>(documents: Vec<ShardDocument>) -> anyhow::Result<evaluation::MergedSweep<C, R>>
where
    C: DeserializeOwned + Serialize,
    R: DeserializeOwned + Serialize,
{
    let shards = documents
        .into_iter()
        .map(ShardDocument::typed)
        .collect::<evaluation::Result<Vec<_>>>()?;
    Ok(evaluation::merge(shards)?)
}

fn merge_reproduce(
    args: &Args,
    documents: Vec<ShardDocument>,
    inputs: &[(String, PathBuf)],
    start: Instant,
) -> anyhow::Result<()> {
    let merged: evaluation::MergedSweep<
        evaluation::ReproduceContext,
        Vec<evaluation::LearnCellOutcome>,
    > = merged(documents)?;
    let to = Destinations {
        out: args.out.clone(),
        latex_dir: args
            .latex_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from("paper/tables")),
        readme: args.readme.clone(),
        force: args.force,
    };
    let context = &merged.context;
    let plan =
        super::reproduce::plan_outputs(inputs, context.result_files(), context.latex_files(), &to)?;
    let staged = plan.set.prepare()?;
    let outcome = evaluation::merged_run(merged)?;
    super::reproduce::write_outcome(&outcome, staged, plan.ids, &to, start)
}

fn merge_ablations(
    args: &Args,
    documents: Vec<ShardDocument>,
    inputs: &[(String, PathBuf)],
    start: Instant,
) -> anyhow::Result<()> {
    let merged = merged(documents)?;
    let (set, folder) = super::ablations::plan_outputs(inputs, &args.out, args.force)?;
    let staged = set.prepare()?;
    let outcome = evaluation::merged_ablations(merged)?;
    super::ablations::write_outcome(&outcome, staged, folder, &args.out, start)
}

fn merge_spread(
    args: &Args,
    documents: Vec<ShardDocument>,
    inputs: &[(String, PathBuf)],
) -> anyhow::Result<()> {
    let merged: evaluation::MergedSweep<evaluation::SpreadContext, Vec<evaluation::CellSummary>> =
        merged(documents)?;
    let mut set = OutputSet::new(super::meta_train::PRODUCER);
    for (what, path) in inputs {
        set.input(format!("the {what} input"), path);
    }
    let file = set.file(&args.out, "--out", Existing::from_force(args.force));
    let staged = set.prepare()?;
    let document = evaluation::spread_document(&merged.context, &merged.items, &merged.results);
    let how = format!("merged from {} shards", merged.shards.len());
    super::seed_spread::print_spread(&document.cells, &merged.context.seeds, &how);
    super::seed_spread::write_spread(staged.path(file), &args.out, &document)?;
    staged.commit()?;
    say!("wrote {}", args.out.display());
    Ok(())
}
