//! `learn ablations`: every variant of `experiments/variants.json` on every cell, over its seeds;
//! with `--shard K/N`, one shard of that work (merged by `learn merge`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use evaluation::{AblationsOutcome, ShardSpec, VariantsConfig};
use output_set::{Existing, FolderId, OutputSet, Staged};

use super::Global;
use super::progress::ItemLines;
use super::shard::{SHARD_HELP, ShardOutputs, parse_shard};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The variants configuration (variants, seeds, headline, figure variant).
    #[arg(
        long,
        default_value = "experiments/variants.json",
        conflicts_with = "render_only"
    )]
    pub config: PathBuf,
    /// Where ablations.{json,md} and figures/ are written.
    #[arg(long, default_value = "results/ablations")]
    pub out: PathBuf,
    /// The project root: relative paths in the configuration start here.
    #[arg(long, default_value = ".", conflicts_with = "render_only")]
    pub root: PathBuf,
    /// Replace the files an earlier `learn ablations` wrote in --out (files it did not write are
    /// never replaced).
    #[arg(long)]
    pub force: bool,
    /// Only rewrite `<out>/ablations.md` from an existing `ablations.json` (no fitting; --config
    /// and --root do not apply).
    #[arg(long)]
    pub render_only: bool,
    #[arg(long, value_name = "K/N", value_parser = parse_shard, allow_hyphen_values = true, help = SHARD_HELP,
          requires = "out", conflicts_with = "render_only")]
    pub shard: Option<ShardSpec>,
}

/// What the output manifest records as the writer of these files.
pub const PRODUCER: &str = "ablations";
/// The writer of a shard's result (never removes, nor is removed by, the run's own files).
const SHARD_PRODUCER: &str = "ablations-shard";

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if args.render_only {
        return render_only(&args);
    }
    let start = Instant::now();
    let config = VariantsConfig::load(&args.config, &args.root)?;
    let inputs = config.input_files("--config");
    if let Some(shard) = args.shard {
        return run_shard(global, &args, &config, &inputs, shard);
    }
    let (set, folder) = plan_outputs(&inputs, &args.out, args.force)?;
    let data_dir = global.data_dir()?;
    let staged = set.prepare()?;
    let outcome = evaluation::run_variants(&config, &data_dir, &progress(global, start))?;
    write_outcome(&outcome, staged, folder, &args.out, start)
}

/// `--shard K/N`: the shard's items only, into `--out/shard.json`.
fn run_shard(
    global: &Global,
    args: &Args,
    config: &evaluation::CheckedVariants,
    inputs: &[(String, PathBuf)],
    shard: ShardSpec,
) -> anyhow::Result<()> {
    let outputs = ShardOutputs::plan(SHARD_PRODUCER, &args.out, args.force, inputs)?;
    let data_dir = global.data_dir()?;
    let staged = outputs.prepare()?;
    let start = Instant::now();
    let file = evaluation::run_variants_shard(config, &data_dir, &progress(global, start), shard)?;
    staged.commit(&file)
}

/// A line per finished item, only on a terminal and without --quiet (a log gets the summary).
fn progress(global: &Global, start: Instant) -> ItemLines {
    ItemLines {
        show: global.show_progress(),
        start,
    }
}

/// The ablations' output set, checked: `ablations.{json,md}` and `figures/` in `out`; `inputs`
/// (what, path) may be none of them.
pub fn plan_outputs(
    inputs: &[(String, PathBuf)],
    out: &Path,
    force: bool,
) -> anyhow::Result<(OutputSet, FolderId)> {
    let mut set = OutputSet::new(PRODUCER);
    for (what, path) in inputs {
        set.input(format!("the {what} input"), path);
    }
    let folder = set.folder(out, "--out", Existing::from_force(force));
    for file in evaluation::ablation_files() {
        set.file_in(folder, file);
    }
    // The figures' names depend on the cells: checked when the set is committed.
    set.subfolder_in(folder, "figures");
    set.check()?;
    Ok((set, folder))
}

/// Writes `outcome` into the staged folder, commits it and prints the tables.
pub fn write_outcome(
    outcome: &AblationsOutcome,
    staged: Staged,
    folder: FolderId,
    out: &Path,
    start: Instant,
) -> anyhow::Result<()> {
    super::staged_write(&staged, || {
        evaluation::write_ablations(outcome, staged.dir(folder))
    })?;
    let written = staged.commit()?;
    note!(
        "{:>7.1} s  total; wrote {} files under {}",
        start.elapsed().as_secs_f64(),
        written.len(),
        out.display()
    );
    say!(
        "{}",
        report::ablations_markdown(&outcome.ablations.tables())
    );
    Ok(())
}

/// `--render-only`: `ablations.md` again from the `ablations.json` of an earlier run.
fn render_only(args: &Args) -> anyhow::Result<()> {
    let json = args.out.join("ablations.json");
    let text = bounded_read::read_json_text(&json)
        .map_err(|e| anyhow::anyhow!("{}: {e}", json.display()))?;
    let ablations: evaluation::Ablations = bounded_read::json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}: {e}", json.display()))?;
    let markdown = report::ablations_markdown(&ablations.tables());
    // Only ablations.md is rewritten: the run's other files stay its own.
    let mut set = OutputSet::new(PRODUCER).updating_only_its_files();
    set.input("the ablations.json input", &json);
    let folder = set.folder(&args.out, "--out", Existing::from_force(args.force));
    set.file_in(folder, "ablations.md");
    let staged = set.prepare()?;
    let md = staged.dir(folder).join("ablations.md");
    std::fs::write(&md, &markdown).map_err(|e| anyhow::anyhow!("{}: {e}", md.display()))?;
    staged.commit()?;
    say!("{markdown}");
    Ok(())
}
