//! `learn simulate --scenario FILE --out FILE.csv`: a closed-loop flight of the simulated plant,
//! written as a Neural-Fly log.

use std::path::{Path, PathBuf};

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
    write_readable(&log, &args.out, &args.scenario)?;
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

/// Writes the log to `out` only if the data tools read it back: it is written next to `out`, read
/// with the same checks as `learn data inspect` and `learn mismatch` (layout, plausible ranges),
/// and moved into place; otherwise it is removed and the error names the scenario, the column
/// and the settings likely responsible.
fn write_readable(log: &data::FlightLog, out: &Path, scenario: &Path) -> anyhow::Result<()> {
    let file_name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "flight.csv".to_string());
    let staging = out.with_file_name(format!(".{file_name}.{}.partial", std::process::id()));
    log.write_csv(&staging)?;
    if let Err(error) = data::FlightLog::read(&staging) {
        let _ = std::fs::remove_file(&staging);
        let cause = match &error {
            data::DataError::Implausible {
                column,
                value,
                min,
                max,
                unit,
                quantity,
                ..
            } => format!(
                "its column {column} ({quantity}) reaches {value:.4e}{unit}, outside the range [{min}, {max}]{unit} the data tools accept; check {}",
                likely_settings(column)
            ),
            other => format!("the data tools refuse it: {other}"),
        };
        bail!(
            "{}: the simulated flight is not a usable log ({cause}); nothing written to {}",
            scenario.display(),
            out.display()
        );
    }
    std::fs::rename(&staging, out).map_err(|e| {
        let _ = std::fs::remove_file(&staging);
        anyhow::anyhow!("{}: {e}", out.display())
    })
}

/// The scenario and model settings that drive a logged column.
fn likely_settings(column: &str) -> &'static str {
    match column {
        "p" => "trajectory and noise.position_m",
        "p_d" => "trajectory",
        "v" => "trajectory and noise.velocity_m_s",
        "v_d" => "trajectory",
        "w" => "gains and noise.rate_rad_s",
        "T_sp" => "hover_throttle, gains and the model's mass_kg and mixer.b0",
        "hover_throttle" => "hover_throttle",
        "pwm" => "the model's mixer.pwm_offset and mixer.pwm_scale",
        _ => "the scenario's gains and the model",
    }
}
