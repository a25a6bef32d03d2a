//! `learn explain`: the inputs that dominate each output through ℰ, and the learned equation.

use std::path::PathBuf;

use anyhow::Context;
use data::{ExperimentConditions, FlightLog};
use evaluation::{Segmentation, explain_flight, own_data};
use learn::{EquationRule, Explanation, MetaTrainedModel};

use output_set::{Existing, OutputSet};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A checkpoint written by `learn meta-train` (flights) or `learn meta-train --tasks`.
    pub checkpoint: PathBuf,
    /// The flight to explain over (default: the evaluation flight of the checkpoint's held-out
    /// condition); for a model of CSV tasks, the recording (a CSV with its columns; required).
    #[arg(long, visible_alias = "csv")]
    pub flight: Option<PathBuf>,
    /// For a model of CSV tasks: the rows it adapts on before the explanation, A:B (data rows
    /// from 0, B excluded) [default: the first half of the recording].
    #[arg(long, value_parser = super::evaluate::parse_rows, conflicts_with = "no_adapt")]
    pub support_rows: Option<std::ops::Range<usize>>,
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
    let mut set = OutputSet::new("explain");
    set.input("the checkpoint input", &args.checkpoint);
    set.input("the --conditions input", &args.conditions);
    if let Some(flight) = &args.flight {
        set.input("the --flight input", flight);
    }
    let json_file = args
        .json
        .as_ref()
        .map(|path| set.file(path, "--json", Existing::from_force(args.force)));
    set.check()?;
    let model = MetaTrainedModel::load(&args.checkpoint)?;
    let Some(flights) = model.flights().cloned() else {
        return explain_columns(&args, set, json_file, &model);
    };
    if args.support_rows.is_some() {
        anyhow::bail!(
            "--support-rows applies to models of CSV tasks only (a flight model adapts on the first half of the flight)"
        );
    }
    let flight = match args.flight {
        Some(path) => path,
        None => {
            let conditions = ExperimentConditions::load(&args.conditions)?;
            let name = args
                .condition
                .or(flights.held_out_condition.clone())
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
    set.input("the flight input", &flight);
    let staged = set.prepare()?;
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
    // The paper's segments: the model adapts on the first half of the flight.
    let explanation = explain_flight(&model, &log, Segmentation::PAPER, !args.no_adapt, rule)?;
    // Files first, then words.
    if let (Some(path), Some(file)) = (&args.json, json_file) {
        let value = serde_json::json!({
            "checkpoint": args.checkpoint,
            "flight": flight,
            "protocol": flights.protocol,
            "seed": model.seed,
            "adapted": !args.no_adapt,
            "explanation": explanation,
        });
        let text = serde_json::to_string_pretty(&value)? + "\n";
        std::fs::write(staged.path(file), text).with_context(|| path.display().to_string())?;
        staged.commit()?;
    }
    say!(
        "{} model ({} protocol, seed {}) over {} ({} samples, {})",
        flights.formulation.name(),
        flights.protocol,
        model.seed,
        flight.display(),
        explanation.samples,
        if args.no_adapt {
            "meta-trained, not adapted"
        } else {
            "adapted online on the support half"
        }
    );
    print_explanation(&explanation, args.json.as_deref());
    Ok(())
}

fn print_explanation(explanation: &Explanation, json: Option<&std::path::Path>) {
    for output in &explanation.outputs {
        let inputs: Vec<String> = output
            .inputs
            .iter()
            .map(|i| format!("{} {:.3}", i.input, i.mean_abs_coefficient))
            .collect();
        say!("{}", output.equation);
        say!("    mean |ℰ| per input: {}", inputs.join(", "));
    }
    if let Some(path) = json {
        say!("wrote {}", path.display());
    }
}

/// The explanation of a model of CSV tasks over the recording `--flight`/`--csv`: adapted on
/// `--support-rows` (default the first half) unless `--no-adapt`.
fn explain_columns(
    args: &Args,
    mut set: OutputSet,
    json_file: Option<output_set::FileId>,
    model: &MetaTrainedModel,
) -> anyhow::Result<()> {
    let Some(recording_path) = &args.flight else {
        anyhow::bail!(
            "{}: a model of CSV tasks: pass --csv FILE, a recording with its columns",
            args.checkpoint.display()
        );
    };
    if args.condition.is_some() {
        anyhow::bail!("--condition applies to flight models only");
    }
    let columns = learn::column_training(model, &args.checkpoint.display().to_string())?;
    set.input("the --csv input", recording_path);
    let staged = set.prepare()?;
    let recording = own_data::read_recording(recording_path, &columns.spec())?;
    let support = match (&args.support_rows, args.no_adapt) {
        (_, true) => None,
        (Some(rows), false) => Some(rows.clone()),
        (None, false) => Some(0..recording.rows() / 2),
    };
    let rule = EquationRule {
        max_terms: args.max_terms,
        ..EquationRule::default()
    };
    // Adapting on rows of the recording needs its sampling interval to be the tasks'.
    if support.is_some() {
        own_data::check_interval(columns, &recording)?;
    }
    let explanation = learn::explain_recording(
        model,
        own_data::recording(&recording),
        support.clone(),
        rule,
    )?;
    if let (Some(path), Some(file)) = (&args.json, json_file) {
        let value = serde_json::json!({
            "checkpoint": args.checkpoint,
            "recording": recording_path,
            "seed": model.seed,
            "adapted_on_rows": support.as_ref().map(|rows| [rows.start, rows.end]),
            "explanation": explanation,
        });
        let text = serde_json::to_string_pretty(&value)? + "\n";
        std::fs::write(staged.path(file), text).with_context(|| path.display().to_string())?;
        staged.commit()?;
    }
    say!(
        "model of CSV tasks (seed {}) over {} ({} samples, {}); coefficients in the units of the targets",
        model.seed,
        recording_path.display(),
        explanation.samples,
        match &support {
            Some(rows) => format!("adapted online on rows {}:{}", rows.start, rows.end),
            None => "meta-trained, not adapted".to_string(),
        }
    );
    print_explanation(&explanation, args.json.as_deref());
    Ok(())
}
