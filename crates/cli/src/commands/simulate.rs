//! `learn simulate --scenario FILE --out FILE.csv`: a closed-loop flight of the simulated plant,
//! written as a Neural-Fly log, or as a PX4 ULog when the output ends in `.ulg`
//! (`data::ulog::flight_log_as_ulog`; read back with `experiments/layouts/simulator-ulog.json`).

use std::path::PathBuf;

use anyhow::Context;
use output_set::{Existing, OutputSet};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario JSON (model, trajectory, effects, noise, seed).
    #[arg(long)]
    pub scenario: PathBuf,
    /// Output CSV, or ULog when it ends in .ulg (never the scenario or the model it names, even
    /// with --force).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
    let mut set = OutputSet::new("simulate");
    set.input("the --scenario input", &args.scenario);
    let file = set.file(&args.out, "--out", Existing::from_force(args.force));
    set.check()?;
    // The model the scenario names is read as much as the scenario itself, under the project's
    // JSON policy (no key given twice).
    super::read_policy_json(&args.scenario)?;
    let (scenario, model) = physics::Scenario::load(&args.scenario)?;
    let model_path = scenario.model_path(&args.scenario);
    super::read_policy_json(&model_path)?;
    set.input(
        format!(
            "the model that the --scenario {} reads",
            args.scenario.display()
        ),
        &model_path,
    );
    let staged = set.prepare()?;
    let name = args
        .out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "flight".to_string());
    let log = physics::simulate(&model, &scenario, &name)
        .with_context(|| format!("{}", args.scenario.display()))?;
    if data::layout::is_ulog(&args.out) {
        super::staged_write(&staged, || {
            let bytes = data::ulog::flight_log_as_ulog(&log)?;
            std::fs::write(staged.path(file), bytes).map_err(|e| e.to_string())
        })?;
    } else {
        super::staged_write(&staged, || {
            physics::write_readable(&log, staged.path(file), &args.scenario)
        })?;
    }
    staged.commit()?;
    let effects: Vec<&str> = scenario
        .effects
        .ids()
        .into_iter()
        .map(physics::EffectId::name)
        .collect();
    say!(
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
