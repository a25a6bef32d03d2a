//! `learn reproduce`: the paper's tables and figures from one command; with `--shard K/N`, one
//! shard of its work (merged by `learn merge`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::bail;
use evaluation::{OutputPaths, RunConfig, RunOutcome, ShardSpec};
use output_set::{Existing, FileId, FolderId, OutputSet, Staged};

use super::Global;
use super::progress::StageBars;
use super::shard::{SHARD_HELP, ShardOutputs, parse_shard};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The run configuration (formulations, conditions, split, SINDy and LeARN settings, seeds).
    #[arg(long, default_value = "experiments/reproduce.json")]
    pub config: PathBuf,
    /// Where tables/, figures/, summary.json and timings.json are written (with --shard: the
    /// folder of the shard's result).
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Where the LaTeX tables are written.
    #[arg(long, default_value = "paper/tables")]
    pub latex_dir: PathBuf,
    /// Also rewrite the generated results block of this README.
    #[arg(long)]
    pub readme: Option<PathBuf>,
    /// The project root: relative paths in the run configuration start here.
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
    /// Replace the files an earlier `learn reproduce` wrote in --out and --latex-dir (files it
    /// did not write are never replaced).
    #[arg(long)]
    pub force: bool,
    #[arg(long, value_name = "K/N", value_parser = parse_shard, allow_hyphen_values = true, help = SHARD_HELP,
          requires = "out", conflicts_with_all = ["latex_dir", "readme"])]
    pub shard: Option<ShardSpec>,
}

/// What the output manifests record as the writer of these files.
pub const PRODUCER: &str = "reproduce";
/// The writer of a shard's result (never removes, nor is removed by, the run's own files).
const SHARD_PRODUCER: &str = "reproduce-shard";

/// Where a reproduce run, or the merge of its shards, writes.
pub struct Destinations {
    pub out: PathBuf,
    pub latex_dir: PathBuf,
    pub readme: Option<PathBuf>,
    pub force: bool,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let config = RunConfig::load(&args.config, &args.root)?;
    let inputs = config.input_files("--config");
    if let Some(shard) = args.shard {
        return run_shard(global, &args, &config, &inputs, shard);
    }
    let to = Destinations {
        out: args.out.clone(),
        latex_dir: args.latex_dir.clone(),
        readme: args.readme.clone(),
        force: args.force,
    };
    let plan = plan_outputs(
        &inputs,
        evaluation::result_files(&config),
        evaluation::latex_files(&config),
        &to,
    )?;
    let data_dir = global.data_dir()?;
    let staged = plan.set.prepare()?;
    note!(
        "run '{}' on {} ({})",
        config.raw.name,
        data_dir.display(),
        worker_threads()
    );
    let progress = StageBars::new(global.show_progress());
    let outcome = evaluation::run(&config, &data_dir, &args.root, &progress)?;
    write_outcome(&outcome, staged, plan.ids, &to, start)
}

/// `--shard K/N`: the shard's items only, into `--out/shard.json`.
fn run_shard(
    global: &Global,
    args: &Args,
    config: &evaluation::CheckedRunConfig,
    inputs: &[(String, PathBuf)],
    shard: ShardSpec,
) -> anyhow::Result<()> {
    let outputs = ShardOutputs::plan(SHARD_PRODUCER, &args.out, args.force, inputs)?;
    let data_dir = global.data_dir()?;
    let staged = outputs.prepare()?;
    note!(
        "run '{}' shard {shard} on {} ({})",
        config.raw.name,
        data_dir.display(),
        worker_threads()
    );
    let progress = StageBars::new(global.show_progress());
    let file = evaluation::run_shard(config, &data_dir, &args.root, &progress, shard)?;
    staged.commit(&file)
}

/// Writes `outcome` into the staged set (tables, figures, summary, timings, LaTeX, README block),
/// commits it and prints the tables.
pub fn write_outcome(
    outcome: &RunOutcome,
    staged: Staged,
    ids: PlanIds,
    to: &Destinations,
    start: Instant,
) -> anyhow::Result<()> {
    let staging = OutputPaths {
        results_dir: staged.dir(ids.results).to_path_buf(),
        latex_dir: staged.dir(ids.latex).to_path_buf(),
    };
    evaluation::write_outputs(outcome, &staging)?;
    if let (Some(readme), Some(file)) = (&to.readme, ids.readme) {
        let text = evaluation::updated_readme(outcome, readme, &to.out.join("figures"))?;
        std::fs::write(staged.path(file), text)
            .map_err(|e| anyhow::anyhow!("{}: {e}", readme.display()))?;
    }
    let written = staged.commit()?;
    note!(
        "{:>7.2} s  total; wrote {} files under {} and {}",
        start.elapsed().as_secs_f64(),
        written.len(),
        to.out.display(),
        to.latex_dir.display()
    );
    for table in &outcome.tables {
        say!("\n{}", report::markdown(table));
    }
    Ok(())
}

/// The run's output set, checked before any directory is made: the results and LaTeX folders
/// (their files replaced only with --force, and only those `learn reproduce` wrote), the README
/// to update, and every input (none may be an output).
pub struct Plan {
    pub set: OutputSet,
    pub ids: PlanIds,
}

/// Where each part of a [`Plan`] goes in its set.
#[derive(Clone, Copy)]
pub struct PlanIds {
    results: FolderId,
    latex: FolderId,
    readme: Option<FileId>,
}

/// Plans `result_files` in `to.out`, `latex_files` in `to.latex_dir` and the README; `inputs`
/// (what, path) may be none of them.
pub fn plan_outputs(
    inputs: &[(String, PathBuf)],
    result_files: Vec<PathBuf>,
    latex_files: Vec<PathBuf>,
    to: &Destinations,
) -> anyhow::Result<Plan> {
    let mut set = OutputSet::new(PRODUCER);
    for (what, path) in inputs {
        set.input(format!("the {what} input"), path);
    }
    let existing = Existing::from_force(to.force);
    let results = set.folder(&to.out, "--out", existing);
    for file in result_files {
        set.file_in(results, file);
    }
    let latex = set.folder(&to.latex_dir, "--latex-dir", existing);
    for file in latex_files {
        set.file_in(latex, file);
    }
    // The README is named to be updated: replaced (its block only) without --force, but never
    // an input or another output.
    let readme = match &to.readme {
        Some(readme) => Some(readme_in(&mut set, readme)?),
        None => None,
    };
    set.check()?;
    Ok(Plan {
        set,
        ids: PlanIds {
            results,
            latex,
            readme,
        },
    })
}

/// The README to update, planned in `set` after its other outputs (which it may not be); its
/// results block is checked.
fn readme_in(set: &mut OutputSet, readme: &Path) -> anyhow::Result<FileId> {
    if let Some(output) = set.targets().iter().find(|t| super::same_file(t, readme)) {
        bail!(
            "{}: the --readme to update is also an output of the run ({})",
            readme.display(),
            output.display()
        );
    }
    let file = set.file(readme, "--readme", Existing::Replace);
    set.check()?;
    evaluation::check_readme(readme)?;
    Ok(file)
}

/// "1 thread", "4 threads": the pool the run's parallel work uses.
fn worker_threads() -> String {
    match evaluation::worker_threads() {
        1 => "1 thread".to_string(),
        count => format!("{count} threads"),
    }
}
