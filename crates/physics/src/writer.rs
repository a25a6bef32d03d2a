//! Writing a simulated flight as a log the data tools read.

use std::path::Path;

use data::{DataError, FlightLog, Spacing};

use crate::error::{PhysicsError, Result};

/// Writes the simulated `log` to `out` only if the data tools read it back: it is written next to
/// `out`, read with [`FlightLog::read_spaced`] (layout, plausible ranges; any spacing, as a
/// scenario's `log_timing` may space the rows) and moved into place. Otherwise nothing is left behind and the error
/// ([`PhysicsError::UnusableLog`]) names the `scenario` file it was simulated from, the refused
/// column and the scenario and model settings likely responsible.
pub fn write_readable(log: &FlightLog, out: &Path, scenario: &Path) -> Result<()> {
    let file_name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "flight.csv".to_string());
    let staging = out.with_file_name(format!(".{file_name}.{}.partial", std::process::id()));
    log.write_csv(&staging)?;
    if let Err(error) = FlightLog::read_spaced(&staging, Spacing::Any) {
        let _ = std::fs::remove_file(&staging);
        let cause = match &error {
            DataError::Implausible {
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
        return Err(PhysicsError::UnusableLog {
            scenario: scenario.to_path_buf(),
            out: out.to_path_buf(),
            cause,
        });
    }
    std::fs::rename(&staging, out).map_err(|source| {
        let _ = std::fs::remove_file(&staging);
        PhysicsError::Io {
            path: out.to_path_buf(),
            source,
        }
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
