//! `learn meta-train --tasks GLOB --time t --state x,y --control u [--config FILE] --out MODEL.json`:
//! LeARN meta-trained on your own recordings, one task per CSV file (or per value of
//! `--task-column`), saved as a checkpoint that `learn evaluate` and `learn explain` read.

use std::path::PathBuf;

use anyhow::bail;
use evaluation::own_data::{data_files, read_tasks, recording};
use indicatif::{ProgressBar, ProgressStyle};
use learn::{ColumnSpec, TaskConfig, TaskSet, TaskSource};
use output_set::{Existing, OutputSet};
use sindy::Derivative;

use super::Global;
use super::meta_train::Args;

/// The options of `meta-train` on CSV tasks.
#[derive(clap::Args, Debug)]
pub struct TaskArgs {
    /// Meta-train on your own data: every CSV file matched by this glob pattern is one task
    /// (quote it); with --task-column, one CSV file holding every task.
    #[arg(long, conflicts_with_all = ["formulations", "condition", "checkpoints", "published", "seed_spread", "protocol", "conditions"])]
    pub tasks: Option<String>,
    /// Split the one --tasks file into tasks by the value of this column (each task's rows
    /// consecutive).
    #[arg(long, requires = "tasks")]
    pub task_column: Option<String>,
    /// The time column of the tasks (uniformly sampled, strictly increasing, seconds).
    #[arg(long, default_value = "t")]
    pub time: String,
    /// State columns, comma-separated; `v[0]` is element 0 of a list column `v` (`[1.0, 2.0]`).
    #[arg(long, value_delimiter = ',', requires = "tasks")]
    pub state: Vec<String>,
    /// Control columns, comma-separated, named as --state.
    #[arg(long, value_delimiter = ',', requires = "tasks")]
    pub control: Vec<String>,
    /// Derivative estimator of the targets: forward, central, savgol or savgol:WINDOW:ORDER.
    #[arg(long, default_value = "central", value_parser = super::sindy::parse_derivative)]
    pub derivative: Derivative,
}

impl TaskArgs {
    /// Refuses the task options that only mean something with --tasks (those with defaults).
    pub fn refuse_without_tasks(&self) -> anyhow::Result<()> {
        if self.time != "t" || self.derivative != Derivative::Central {
            bail!("--time and --derivative apply to --tasks only");
        }
        Ok(())
    }

    /// The task source and the columns, checked before any file is read.
    fn source_and_spec(&self) -> anyhow::Result<(TaskSource, ColumnSpec)> {
        let Some(pattern) = &self.tasks else {
            bail!("--tasks is missing (a bug)");
        };
        if self.state.is_empty() {
            bail!("--tasks needs --state (the state columns, comma-separated)");
        }
        let spec = ColumnSpec {
            time: self.time.clone(),
            state: self.state.clone(),
            control: self.control.clone(),
            derivative: self.derivative,
        };
        spec.check()
            .map_err(|message| anyhow::anyhow!("--state/--control: {message}"))?;
        let source = match &self.task_column {
            Some(column) => TaskSource::Column {
                file: PathBuf::from(pattern),
                column: column.clone(),
            },
            None => TaskSource::Files {
                pattern: pattern.clone(),
            },
        };
        Ok((source, spec))
    }
}

/// A bar over the meta-iterations on standard error, only on a terminal and without --quiet.
fn iteration_bar(show: bool, iterations: usize) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(iterations as u64).with_message("meta-train");
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:32}] {pos}/{len} iterations, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

pub fn run(global: &Global, args: &Args) -> anyhow::Result<()> {
    let (source, spec) = args.tasks.source_and_spec()?;
    let Some(out) = &args.out else {
        bail!("--tasks needs --out MODEL.json (where the meta-trained model is written)");
    };
    let mut settings = TaskConfig::load(args.config.as_deref())?;
    if let Some(seed) = args.seed {
        settings = settings.with_seed(seed);
    }
    let mut set = OutputSet::new("meta-train");
    if let Some(config) = &args.config {
        set.input("the --config input", config);
    }
    if let TaskSource::Column { file, .. } = &source {
        set.input("the --tasks input", file);
    }
    let model_file = set.file(out, "--out", Existing::from_force(args.force));
    set.check()?;
    let tasks = read_tasks(&source, &spec)?;
    // No task may be the output, however its path is spelt.
    for task in &tasks {
        set.input(format!("the task {}", task.name), &task.path);
    }
    let staged = set.prepare()?;
    let files = data_files(&tasks)?;
    let bar = iteration_bar(
        global.show_progress(),
        settings.get().meta_training.iterations,
    );
    let recordings: Vec<learn::Recording> = tasks.iter().map(recording).collect();
    let model = learn::meta_train_tasks(
        TaskSet {
            source: &source,
            spec: &spec,
            tasks: &recordings,
            files,
        },
        &settings,
        &|done| bar.set_position(done as u64),
    );
    bar.finish_and_clear();
    let model = model?;
    super::staged_write(&staged, || model.save(staged.path(model_file)))?;
    staged.commit()?;
    let rows: usize = tasks.iter().map(|t| t.rows()).sum();
    say!(
        "meta-trained on {} tasks ({rows} rows; inputs {}; outputs {}), seed {}, final meta-loss {:.4} (targets in units of their standard deviation)",
        tasks.len(),
        model.input_names().join(", "),
        model.output_names().join(", "),
        model.seed,
        model.meta_loss_history.last().copied().unwrap_or(f64::NAN),
    );
    say!("wrote {}", out.display());
    Ok(())
}
