//! Subcommands of `learn`.

mod ablations;
mod check_paper;
mod conditions;
mod evaluate;
mod explain;
mod inspect;
mod memory;
mod merge;
mod meta_train;
mod meta_train_tasks;
mod mismatch;
mod own_data_example;
mod progress;
mod reproduce;
mod seed_spread;
mod shard;
mod simulate;
mod sindy;
mod sindy_apply;

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};

/// Whether two paths name the same file whatever their spelling (see [`output_set::paths::same_file`]).
pub use output_set::paths::same_file;

/// Reproduces the LeARN paper against SINDy on the Neural-Fly quadrotor flights, fits SINDy and
/// LeARN on your own recordings, and names the physics a nominal model leaves out of real flights.
#[derive(Parser, Debug)]
#[command(
    name = "learn",
    version,
    after_help = "Start in the repository root with `make reproduce` (the paper's tables and \
                  figures) or `make test`; the README says what each command writes."
)]
pub struct Cli {
    /// Flight data directory (default: $NEURAL_FLY_DIR, then data/neural-fly).
    #[arg(long, global = true)]
    pub data: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, global = true)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Flight logs: `learn data inspect FLIGHT.csv` shows a log's duration, rate, columns, ranges
    /// and problems; `learn data inspect LOG.ulg` a PX4 log's vehicle, airborne time and the
    /// rates of the topics a flight analysis reads.
    Data {
        #[command(subcommand)]
        command: DataCommand,
    },
    /// List the wind conditions of the experiment and which flight files are present.
    Conditions(conditions::Args),
    /// Fit a SINDy model on numeric CSV recordings: print its equations, optionally save it as
    /// JSON; `learn sindy predict|simulate` apply a saved model to new data.
    Sindy(sindy::Args),
    /// Run SINDy and LeARN on every formulation and condition: tables, figures, summary.
    Reproduce(reproduce::Args),
    /// Compare the latest results with the paper's numbers within declared tolerances.
    CheckPaper(check_paper::Args),
    /// Meta-train LeARN, adapt online on each evaluation flight, print and save the LeARN columns;
    /// with --tasks, meta-train on your own CSV recordings and save the model.
    MetaTrain(meta_train::Args),
    /// Adapt a model of `meta-train --tasks` on rows of a new recording, score other rows, next
    /// to SINDy fitted on the same rows.
    Evaluate(evaluate::Args),
    /// The inputs that dominate each output of a LeARN checkpoint through ℰ, and its equations.
    Explain(explain::Args),
    /// Simulate a closed-loop flight of the plant (nominal model plus effects) as a Neural-Fly log.
    Simulate(simulate::Args),
    /// Locate where a recording disagrees with a nominal model, name and fit the missing physics.
    Mismatch(mismatch::Args),
    /// Every variant of experiments/variants.json on every cell over its seeds: ablation tables.
    Ablations(ablations::Args),
    /// The worked example of LeARN on your own data: a simulated family of oscillators, its
    /// learning curve against SINDy and ridge.
    OwnDataExample(own_data_example::Args),
    /// Put the shards of a sharded run (`--shard K/N`) together: the unsharded run's files.
    Merge(merge::Args),
}

#[derive(Subcommand, Debug)]
pub enum DataCommand {
    /// Duration, rate, columns, ranges and problems of one flight log (CSV), or the vehicle,
    /// airborne time and topic rates of a PX4 ULog (`.ulg`).
    Inspect(inspect::Args),
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    let global = Global {
        data: cli.data,
        quiet: cli.quiet,
    };
    match cli.command {
        Command::Data {
            command: DataCommand::Inspect(args),
        } => inspect::run(&global, args),
        Command::Conditions(args) => conditions::run(&global, args),
        Command::Sindy(args) => sindy::run(&global, args),
        Command::Reproduce(args) => reproduce::run(&global, args),
        Command::CheckPaper(args) => check_paper::run(&global, args),
        Command::MetaTrain(args) => meta_train::run(&global, args),
        Command::Evaluate(args) => evaluate::run(&global, args),
        Command::Explain(args) => explain::run(&global, args),
        Command::Simulate(args) => simulate::run(&global, args),
        Command::Mismatch(args) => mismatch::run(&global, args),
        Command::Ablations(args) => ablations::run(&global, args),
        Command::OwnDataExample(args) => own_data_example::run(&global, args),
        Command::Merge(args) => merge::run(&global, args),
    }
}

impl Cli {
    /// Combinations of options that clap cannot express, refused as usage errors (exit code 2)
    /// as clap's own are.
    pub fn validated(self) -> Result<Self, clap::Error> {
        if let Command::MetaTrain(args) = &self.command
            && let Some(message) = args.out_without_shard()
        {
            let mut command = <Self as clap::CommandFactory>::command();
            return Err(command.error(clap::error::ErrorKind::ArgumentConflict, message));
        }
        Ok(self)
    }
}

/// Options every subcommand may use.
#[derive(Debug, Clone)]
pub struct Global {
    pub data: Option<PathBuf>,
    pub quiet: bool,
}

impl Global {
    /// The data directory, resolved as documented in the README.
    pub fn data_dir(&self) -> anyhow::Result<PathBuf> {
        Ok(data::resolve_data_dir(self.data.as_deref())?)
    }

    /// The data directory when there is one: `None` only when none was given (no `--data`, no
    /// `$NEURAL_FLY_DIR`) and the default is absent; a given one that is not a directory is an
    /// error naming it, as for [`Global::data_dir`].
    pub fn optional_data_dir(&self) -> anyhow::Result<Option<PathBuf>> {
        Ok(data::find_data_dir(self.data.as_deref())?)
    }

    /// Whether progress bars may be drawn (not quiet, standard error is a terminal).
    pub fn show_progress(&self) -> bool {
        use std::io::IsTerminal;
        !self.quiet && std::io::stderr().is_terminal()
    }
}

/// Runs `write` (a writer given the staging paths of `staged`), naming the final paths in its
/// error rather than the staging ones.
pub fn staged_write<T, E: std::fmt::Display>(
    staged: &output_set::Staged,
    write: impl FnOnce() -> Result<T, E>,
) -> anyhow::Result<T> {
    write().map_err(|error| anyhow::anyhow!(staged.in_final_terms(&error.to_string())))
}

/// Reads a JSON file the run will read through a library that does not apply the project's JSON
/// policy itself (a nominal model): bounded size, a regular file, no key given twice. Returns the
/// text without a byte-order mark.
pub fn read_policy_json(path: &Path) -> anyhow::Result<String> {
    let text = bounded_read::read_json_text(path)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let text = bounded_read::json::checked_text(&text)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok(text.to_string())
}
