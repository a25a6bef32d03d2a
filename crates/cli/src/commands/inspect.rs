//! `learn data inspect FILE`: a Neural-Fly CSV flight log, or a PX4 ULog (`.ulg`), whose airframe
//! parameters may be written as a vehicle description (`--vehicle-out`).

use std::path::{Path, PathBuf};

use data::FlightLog;
use output_set::{Existing, FileId, OutputSet};

use super::Global;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A Neural-Fly CSV flight log, or a PX4 ULog file (`.ulg`).
    pub file: PathBuf,
    /// For a ULog: also write the vehicle description its airframe parameters give (`CA_ROTOR*`,
    /// `THR_MDL_FAC`) to this JSON file, for a nominal model's `vehicle`.
    #[arg(long)]
    pub vehicle_out: Option<PathBuf>,
    /// Overwrite an existing --vehicle-out file.
    #[arg(long)]
    pub force: bool,
}

/// The smallest and the largest of `values` (infinities reversed when there are none).
fn extremes<'a>(values: impl IntoIterator<Item = &'a f64>) -> (f64, f64) {
    values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        })
}

fn range3(name: &str, values: &[[f64; 3]]) -> String {
    let mut parts = Vec::new();
    for (axis, label) in ["x", "y", "z"].iter().enumerate() {
        let (lo, hi) = extremes(values.iter().map(|v| &v[axis]));
        parts.push(format!("{label} [{lo:.3}, {hi:.3}]"));
    }
    format!("  {name:<16} {}", parts.join("  "))
}

/// The columns the log uses, as found in the file: `q` or `R` may be absent (one is derived from the
/// other), the optional ones may be absent, and columns the log does not use are listed apart.
fn column_summary(columns: &[String]) -> String {
    let present = |name: &str| columns.iter().any(|c| c == name);
    const USED: [&str; 9] = [
        "t",
        "p",
        "v",
        "q",
        "R",
        "w",
        "T_sp",
        "hover_throttle",
        "pwm",
    ];
    const OPTIONAL: [&str; 5] = ["p_d", "v_d", "q_sp", "fa", "battery_voltage"];
    let used: Vec<String> = USED
        .iter()
        .map(|&name| match name {
            "q" if !present("q") => "q (absent, derived from R)".to_string(),
            "R" if !present("R") => "R (absent, derived from q)".to_string(),
            _ => name.to_string(),
        })
        .collect();
    let optional: Vec<String> = OPTIONAL
        .iter()
        .map(|name| format!("{name}{}", if present(name) { "" } else { " (absent)" }))
        .collect();
    // The unnamed first column of the Neural-Fly logs is the row index.
    let unused: Vec<&str> = columns
        .iter()
        .map(String::as_str)
        .filter(|c| !c.is_empty() && !USED.contains(c) && !OPTIONAL.contains(c))
        .collect();
    let mut summary = format!("{}; optional: {}", used.join(", "), optional.join(", "));
    if !unused.is_empty() {
        summary.push_str(&format!("; not used: {}", unused.join(", ")));
    }
    summary
}

pub fn run(_global: &Global, args: Args) -> anyhow::Result<()> {
    if data::layout::is_ulog(&args.file) {
        // The output is proved writable before the log is read.
        let output = match &args.vehicle_out {
            Some(out) => {
                let mut set = OutputSet::new("data inspect");
                set.input("the inspected log", &args.file);
                let file = set.file(out, "--vehicle-out", Existing::from_force(args.force));
                set.check()?;
                Some((set, file, out))
            }
            None => None,
        };
        inspect_ulog(&args.file)?;
        return match output {
            Some((set, file, out)) => write_vehicle(&args.file, set, file, out),
            None => Ok(()),
        };
    }
    if args.vehicle_out.is_some() {
        anyhow::bail!(
            "{}: --vehicle-out reads a PX4 ULog's airframe parameters; this is not a .ulg file",
            args.file.display()
        );
    }
    // Any spacing: a real logger's jitter, drops and gaps are reported, not refused.
    let (log, columns) = FlightLog::read_with_columns(&args.file, data::Spacing::Any)?;
    let n = log.len();
    let dt = log.sample_interval();
    say!("file:      {}", args.file.display());
    if let Some(meta) = &log.meta {
        say!(
            "flight:    vehicle {}, trajectory {}, controller {}, condition {}",
            meta.vehicle,
            meta.trajectory,
            meta.method,
            meta.condition
        );
    }
    say!("samples:   {n}");
    say!("duration:  {:.3} s", log.time[n - 1] - log.time[0]);
    say!("rate:      {:.3} Hz (mean dt = {dt:.6} s)", 1.0 / dt);
    if let Some(timing) = log.sample_timing() {
        // `report` depends on no crate that computes: the timing reaches it as JSON.
        let view: report::sample_timing::SampleTiming =
            serde_json::from_value(serde_json::to_value(timing)?)?;
        say!(
            "{}",
            report::sample_timing::sample_timing_text(&view).trim_end()
        );
    }
    say!("columns:   {}", column_summary(&columns));
    say!("ranges:");
    say!("{}", range3("p [m]", &log.position));
    say!("{}", range3("v [m/s]", &log.velocity));
    say!("{}", range3("w [rad/s]", &log.body_rate));
    let (lo, hi) = extremes(&log.thrust_setpoint);
    say!("  {:<16} [{lo:.4}, {hi:.4}]", "T_sp");
    let (lo, hi) = extremes(log.motor_command.rows().flatten());
    say!(
        "  {:<16} [{lo:.1}, {hi:.1}] ({} motors)",
        "pwm",
        log.motor_command.count()
    );
    if let Some(volts) = &log.battery_voltage {
        let (lo, hi) = extremes(volts);
        say!("  {:<16} [{lo:.3}, {hi:.3}]", "battery_voltage [V]");
    }
    let (frame, body, world) = log.rate_frame();
    let mut problems = Vec::new();
    if frame == data::RateFrame::World {
        problems.push(format!(
            "`w` matches the world-frame rate vee(dR Rᵀ) (RMS {world:.4} rad/s) better than the body-frame rate (RMS {body:.4} rad/s)"
        ));
    }
    if let Some(pwm) = log
        .motor_command
        .rows()
        .flatten()
        .find(|p| !(500.0..=2500.0).contains(*p))
    {
        problems.push(format!("a pwm value ({pwm:.1}) lies outside 500..2500"));
    }
    say!("rate frame: {frame:?} (RMS against R: body {body:.4}, world {world:.4} rad/s)");
    if problems.is_empty() {
        say!("problems:  none found");
    } else {
        say!("problems:");
        for problem in problems {
            say!("  - {problem}");
        }
    }
    Ok(())
}

/// Writes the vehicle description of `log`'s airframe parameters to `out`, the `set`'s `file`
/// (atomically).
fn write_vehicle(log: &Path, set: OutputSet, file: FileId, out: &Path) -> anyhow::Result<()> {
    let parameters = data::ulog::parameter_table(&ulog::Log::read(log)?);
    let vehicle = physics::VehicleDescription::from_px4_parameters(&parameters.values)
        .map_err(|error| anyhow::anyhow!("{}: {error}", log.display()))?;
    let staged = set.prepare()?;
    super::staged_write(&staged, || {
        std::fs::write(staged.path(file), vehicle.to_json() + "\n")
    })?;
    staged.commit()?;
    say!(
        "wrote {} ({} rotors, {})",
        out.display(),
        vehicle.rotors.len(),
        vehicle.layout()
    );
    Ok(())
}

/// A ULog: read by `ulog`, inspected by `data`, its airframe parameters read by `physics`,
/// rendered by `report`. `report` depends on no crate that computes, so the inspection reaches it
/// as JSON (whose fields it names, refusing others).
fn inspect_ulog(path: &Path) -> anyhow::Result<()> {
    use report::ulog_inspection::{AirframeSection, UlogInspection, ulog_inspection_text};
    let log = ulog::Log::read(path)?;
    let inspection = serde_json::to_value(data::ulog::inspect(&log))?;
    let view: UlogInspection = serde_json::from_value(inspection)?;
    let parameters = data::ulog::parameter_table(&log);
    let airframe = match physics::vehicle::px4::inspect_airframe(&parameters) {
        Ok(None) => None,
        Ok(Some(airframe)) => Some(AirframeSection::Read(serde_json::from_value(
            serde_json::to_value(airframe)?,
        )?)),
        Err(error) => Some(AirframeSection::Unreadable(error.to_string())),
    };
    say!("file:      {}", path.display());
    say!(
        "{}",
        ulog_inspection_text(&view, airframe.as_ref()).trim_end()
    );
    Ok(())
}
