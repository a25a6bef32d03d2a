//! `learn explain`: the inputs that dominate each output through ℰ, and the learned equation.

use std::path::{Path, PathBuf};

use anyhow::Context;
use data::{ExperimentConditions, FlightLog};
use learn::{EquationRule, MetaTrainedModel, explain_flight};

use super::Global;
use super::refuse_input_as_output;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A checkpoint written by `learn meta-train`.
    pub checkpoint: PathBuf,
    /// The flight to explain over (default: the evaluation flight of the checkpoint's held-out
    /// condition).
    #[arg(long)]
    pub flight: Option<PathBuf>,
    /// The evaluation condition whose flight to explain over (name or label).
    #[arg(long, conflicts_with = "flight")]
    pub condition: Option<String>,
    /// Wind conditions and flight files (not with --flight, which names the flight itself).
    #[arg(
        long,
        default_value = "experiments/conditions.json",
        conflicts_with = "flight"
    )]
    pub conditions: PathBuf,
    /// Explain the meta-trained model itself, without online adaptation on the flight.
    #[arg(long)]
    pub no_adapt: bool,
    /// Most terms per equation (at least 1).
    #[arg(long, default_value_t = 3)]
    pub max_terms: usize,
    /// Also write the explanation as JSON here (never over the checkpoint or the flight).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Replace an existing `--json` file.
    #[arg(long)]
    pub force: bool,
}

pub fn run(global: &Global, args: Args) -> anyhow::Result<()> {
    if args.max_terms == 0 {
        anyhow::bail!("--max-terms: must be at least 1");
    }
    if let Some(path) = &args.json {
        let mut inputs: Vec<(&str, &Path)> = vec![
            ("checkpoint", args.checkpoint.as_path()),
            ("--conditions", args.conditions.as_path()),
        ];
        if let Some(flight) = &args.flight {
            inputs.push(("--flight", flight.as_path()));
        }
        super::check_output(path, "--json", args.force, &inputs)?;
    }
    let model = MetaTrainedModel::load(&args.checkpoint)?;
    let flight = match args.flight {
        Some(path) => path,
        None => {
            let conditions = ExperimentConditions::load(&args.conditions)?;
            let name = args
                .condition
                .or(model.held_out_condition.clone())
                .context(
                    "the checkpoint names no held-out condition: pass --condition or --flight",
                )?;
            let condition = conditions.condition(&name)?;
            conditions.flight_path(
                &global.data_dir()?,
                condition,
                &conditions.evaluation_controller,
            )
        }
    };
    if let Some(path) = &args.json {
        refuse_input_as_output(path, &[("flight", flight.as_path())])?;
    }
    let log = FlightLog::read(&flight)?;
    // Shown and recorded relative to the working directory when it lies below it.
    let flight = std::env::current_dir()
        .ok()
        .and_then(|cwd| flight.strip_prefix(cwd).ok().map(PathBuf::from))
        .unwrap_or(flight);
    let rule = EquationRule {
        max_terms: args.max_terms,
        ..EquationRule::default()
    };
    let explanation = explain_flight(&model, &log, !args.no_adapt, rule)?;
    println!(
        "{} model ({} protocol, seed {}) over {} ({} samples, {})",
        model.formulation.name(),
        model.protocol.name(),
        model.seed,
        flight.display(),
        explanation.samples,
        if args.no_adapt {
            "meta-trained, not adapted"
        } else {
            "adapted online on the support half"
        }
    );
    for output in &explanation.outputs {
        let inputs: Vec<String> = output
            .inputs
            .iter()
            .map(|i| format!("{} {:.3}", i.input, i.mean_abs_coefficient))
            .collect();
        println!("{}", output.equation);
        println!("    mean |ℰ| per input: {}", inputs.join(", "));
    }
    if let Some(path) = &args.json {
        let value = serde_json::json!({
            "checkpoint": args.checkpoint,
            "flight": flight,
            "protocol": model.protocol.name(),
            "seed": model.seed,
            "adapted": !args.no_adapt,
            "explanation": explanation,
        });
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
        }
        std::fs::write(path, serde_json::to_string_pretty(&value)? + "\n")
            .with_context(|| path.display().to_string())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
