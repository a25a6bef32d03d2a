//! `learn reproduce`: the paper's tables and figures from one command.

use std::path::PathBuf;

use anyhow::bail;
use outputs::{Existing, FileId, FolderId, OutputSet};
use pipeline::{OutputPaths, RunConfig, RunOptions, StageTiming};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The run configuration (formulations, conditions, split, SINDy and LeARN settings, seeds).
    #[arg(long, default_value = "experiments/reproduce.json")]
    pub config: PathBuf,
    /// Where tables/, figures/, summary.json and timings.json are written.
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
}

/// What the output manifests record as the writer of these files.
const PRODUCER: &str = "reproduce";

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    let start = std::time::Instant::now();
    let config = RunConfig::load(&args.config, &args.root)?;
    let plan = plan_outputs(&config, &args)?;
    let data_dir = global.data_dir()?;
    if let Some(readme) = &args.readme {
        pipeline::check_readme(readme)?;
    }
    let staged = plan.set.prepare()?;
    let print_stage = |timing: &StageTiming| {
        note!("{:>7.2} s  {}", timing.seconds, timing.stage);
    };
    let options = RunOptions {
        show_progress: global.show_progress(),
        on_stage: &print_stage,
    };
    note!(
        "run '{}' on {} ({} threads)",
        config.raw.name,
        data_dir.display(),
        available_threads()
    );
    let outcome = pipeline::run(&config, &data_dir, &args.root, &options)?;
    let staging = OutputPaths {
        results_dir: staged.dir(plan.results).to_path_buf(),
        latex_dir: staged.dir(plan.latex).to_path_buf(),
    };
    pipeline::write_outputs(&outcome, &staging)?;
    if let (Some(readme), Some(file)) = (&args.readme, plan.readme) {
        let text = pipeline::updated_readme(&outcome, readme, &args.out.join("figures"))?;
        std::fs::write(staged.path(file), text)
            .map_err(|e| anyhow::anyhow!("{}: {e}", readme.display()))?;
    }
    let written = staged.commit()?;
    note!(
        "{:>7.2} s  total; wrote {} files under {} and {}",
        start.elapsed().as_secs_f64(),
        written.len(),
        args.out.display(),
        args.latex_dir.display()
    );
    for table in &outcome.tables {
        say!("\n{}", report::markdown(table));
    }
    Ok(())
}

/// The run's output set, checked before any directory is made: the results and LaTeX folders
/// (their files replaced only with --force, and only those `learn reproduce` wrote), the README
/// to update, and every input (none may be an output).
struct Plan {
    set: OutputSet,
    results: FolderId,
    latex: FolderId,
    readme: Option<FileId>,
}

fn plan_outputs(config: &pipeline::CheckedRunConfig, args: &Args) -> anyhow::Result<Plan> {
    let mut set = OutputSet::new(PRODUCER);
    for (what, path) in config.input_files("--config") {
        set.input(format!("the {what} input"), path);
    }
    let existing = Existing::from_force(args.force);
    let results = set.folder(&args.out, "--out", existing);
    for file in pipeline::result_files(config) {
        set.file_in(results, file);
    }
    let latex = set.folder(&args.latex_dir, "--latex-dir", existing);
    for file in pipeline::latex_files(config) {
        set.file_in(latex, file);
    }
    // The README is named to be updated: replaced (its block only) without --force, but never
    // an input or another output.
    let readme = match &args.readme {
        Some(readme) => {
            if let Some(output) = set.targets().iter().find(|t| super::same_file(t, readme)) {
                bail!(
                    "{}: the --readme to update is also an output of the run ({})",
                    readme.display(),
                    output.display()
                );
            }
            Some(set.file(readme, "--readme", Existing::Replace))
        }
        None => None,
    };
    set.check()?;
    Ok(Plan {
        set,
        results,
        latex,
        readme,
    })
}

fn available_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
