//! Subcommands of `learn`.

mod ablations;
mod check_paper;
mod conditions;
mod explain;
mod inspect;
mod meta_train;
mod mismatch;
mod reproduce;
mod simulate;
mod sindy;

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};

/// Whether two paths name the same file whatever their spelling (see [`data::paths::same_file`]).
pub use data::paths::same_file;

/// Learned-library system identification: SINDy and LeARN on quadrotor flights.
#[derive(Parser, Debug)]
#[command(name = "learn", version, about)]
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
    /// Work with flight logs.
    Data {
        #[command(subcommand)]
        command: DataCommand,
    },
    /// List the wind conditions of the experiment and which flight files are present.
    Conditions(conditions::Args),
    /// Fit a SINDy model on any numeric CSV: print its equations, optionally save it as JSON.
    Sindy(sindy::Args),
    /// Run SINDy and LeARN on every formulation and condition: tables, figures, summary.
    Reproduce(reproduce::Args),
    /// Compare the latest results with the paper's numbers within declared tolerances.
    CheckPaper(check_paper::Args),
    /// Meta-train LeARN, adapt online on each evaluation flight, print and save the LeARN columns.
    MetaTrain(meta_train::Args),
    /// The inputs that dominate each output of a LeARN checkpoint through ℰ, and its equations.
    Explain(explain::Args),
    /// Simulate a closed-loop flight of the plant (nominal model plus effects) as a Neural-Fly log.
    Simulate(simulate::Args),
    /// Locate where a recording disagrees with a nominal model, name and fit the missing physics.
    Mismatch(mismatch::Args),
    /// Every variant of experiments/variants.json on every cell over its seeds: ablation tables.
    Ablations(ablations::Args),
}

#[derive(Subcommand, Debug)]
pub enum DataCommand {
    /// Duration, rate, columns, ranges and problems of one flight log.
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
        Command::Explain(args) => explain::run(&global, args),
        Command::Simulate(args) => simulate::run(&global, args),
        Command::Mismatch(args) => mismatch::run(&global, args),
        Command::Ablations(args) => ablations::run(&global, args),
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

/// Refuses to replace an existing file the user did not ask to overwrite (`--force`).
pub fn refuse_overwrite(path: &Path, force: bool) -> anyhow::Result<()> {
    if path.exists() && !force {
        anyhow::bail!(
            "{}: already exists (pass --force to overwrite)",
            path.display()
        );
    }
    Ok(())
}

/// Checks a file the command is about to write (given by `option`): never one of its `inputs`
/// (option name, path), a place a file can be written, and not an existing file unless `force`.
pub fn check_output(
    output: &Path,
    option: &str,
    force: bool,
    inputs: &[(&str, &Path)],
) -> anyhow::Result<()> {
    refuse_input_as_output(output, inputs)?;
    refuse_unwritable_file(output, option)?;
    refuse_overwrite(output, force)
}

/// Refuses, before any work, a file to write (given by `option`) where none can be written: an
/// existing directory, or a path below something that is not a directory. `--force` cannot help.
pub fn refuse_unwritable_file(output: &Path, option: &str) -> anyhow::Result<()> {
    if output.is_dir() {
        anyhow::bail!(
            "{}: is a directory, not a file to write ({option})",
            output.display()
        );
    }
    refuse_below_a_non_directory(output, option)
}

/// Refuses, before any work, a directory to write files into (given by `option`) that cannot be
/// one: something other than a directory, or a path below something that is not a directory.
pub fn refuse_unwritable_dir(dir: &Path, option: &str) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!(
            "{}: is not a directory ({option} names the directory to write into)",
            dir.display()
        );
    }
    refuse_below_a_non_directory(dir, option)
}

/// Refuses `path` when the nearest of its parents that exists is not a directory (nothing can be
/// created below it).
fn refuse_below_a_non_directory(path: &Path, option: &str) -> anyhow::Result<()> {
    if let Some(parent) = data::paths::non_directory_ancestor(path) {
        anyhow::bail!(
            "{}: {} is not a directory, nothing can be written below it ({option})",
            path.display(),
            parent.display()
        );
    }
    Ok(())
}

/// Refuses an output that is one of the command's inputs (`inputs`: option name, path), whatever
/// `--force` says: writing it would destroy what the run was made from.
pub fn refuse_input_as_output(output: &Path, inputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    if let Some((option, _)) = inputs.iter().find(|(_, input)| same_file(output, input)) {
        anyhow::bail!(
            "{}: is the {option} input, refusing to write over it (even with --force)",
            output.display()
        );
    }
    Ok(())
}

/// Refuses, before any work, a run that would write over or remove one of its `inputs` (what names
/// it, path): a configuration, conditions or published file inside an output directory. No
/// option can allow it: the run would destroy what it was made from.
pub fn refuse_inputs_as_outputs(
    planned: &pipeline::PlannedOutputs,
    inputs: &[(String, PathBuf)],
) -> anyhow::Result<()> {
    for (option, input) in inputs {
        if let Some(output) = planned.clobbers(input, &same_file) {
            anyhow::bail!(
                "{}: is the {option} input, and the run writes {output}: refusing to write over \
                 it (choose another output directory)",
                input.display()
            );
        }
    }
    Ok(())
}
