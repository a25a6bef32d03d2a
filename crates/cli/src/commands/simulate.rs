//! `learn simulate --scenario FILE --out FILE.csv`: a closed-loop flight of the simulated plant,
//! written as a Neural-Fly log.

use std::path::PathBuf;

use anyhow::{Context, bail};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario JSON (model, trajectory, effects, noise, seed).
    #[arg(long)]
    pub scenario: PathBuf,
    /// Output CSV (never the scenario or the model it names, even with --force).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
    if args.out.is_dir() {
        bail!("{}: is a directory, not a CSV file", args.out.display());
    }
    super::check_output(
        &args.out,
        "--out",
        args.force,
        &[("--scenario", &args.scenario)],
    )?;
    let (scenario, model) = physics::Scenario::load(&args.scenario)?;
    // The model the scenario names is read as much as the scenario itself.
    let model_path = scenario.model_path(&args.scenario);
    if super::same_file(&args.out, &model_path) {
        bail!(
            "{}: is the model that the --scenario {} reads, refusing to write over it (even with --force)",
            args.out.display(),
            args.scenario.display()
        );
    }
    let name = args
        .out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "flight".to_string());
    let log = physics::simulate(&model, &scenario, &name)
        .with_context(|| format!("{}", args.scenario.display()))?;
    physics::write_readable(&log, &args.out, &args.scenario)?;
    let effects = scenario.effects.ids();
    println!(
        "wrote {} ({} rows, {:.1} s, seed {}, effects: {})",
        args.out.display(),
        log.len(),
        scenario.duration_s,
        scenario.seed,
        if effects.is_empty() {
            "none".to_string()
        } else {
            effects.join(", ")
        }
    );
    Ok(())
}
