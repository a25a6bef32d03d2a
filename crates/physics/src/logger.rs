//! How a flight log was made: what each row's command column holds relative to the command the
//! vehicle received, and whether the logged body rate went through a filter. A real user knows
//! this from their logging system; the simulator makes logs of every kind, and the mismatch tool
//! reads the same description from the nominal model (`"logger"`), so that the model's prediction
//! passes through the same operations as the recording.

use serde::{Deserialize, Serialize};

/// What the command columns (`pwm`, `T_sp`) of a row at time `t` hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CommandLogging {
    /// The instantaneous command at `t` (a controller faster than the log, sampled).
    #[default]
    Sample,
    /// The mean of the command over the preceding log period `(t − Δt, t]`.
    PeriodMean,
    /// The command issued at `t` and held until the next row (a controller at the log rate).
    Held,
}

impl CommandLogging {
    /// The name used in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sample => "sample",
            Self::PeriodMean => "period_mean",
            Self::Held => "held",
        }
    }
}

/// The largest `|command_time_offset_s|` accepted, s.
pub const MAX_COMMAND_OFFSET_S: f64 = 0.5;
/// The lowest and the highest body-rate low-pass cutoff accepted, Hz.
pub const MIN_RATE_LOW_PASS_HZ: f64 = 1.0;
pub const MAX_RATE_LOW_PASS_HZ: f64 = 10_000.0;

/// The description of a logger.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Logger {
    pub command: CommandLogging,
    /// The command logged in the row at time `t` is the one the vehicle received at
    /// `t + command_time_offset_s` (a logger that samples one control step late: one control
    /// period), s.
    pub command_time_offset_s: f64,
    /// Cutoff of the first-order low-pass the logged body rate `w` went through (a gyro filter),
    /// Hz; none when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_low_pass_hz: Option<f64>,
    /// The rate at which the controller issues its commands, each held until the next, Hz (with
    /// `sample` or `period_mean`). A sampled command then acts, on average, half a control period
    /// after its row's time; and a mixer squares the motor speeds, so the mean thrust over a
    /// `period_mean` row exceeds the thrust of the mean speed by the speeds' spread within the row,
    /// which knowing how many commands a row averages lets the model add back. Unknown when absent:
    /// the command is then taken as a continuous signal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_rate_hz: Option<f64>,
}

impl Logger {
    /// Checks the numbers; the error names the field (without the `logger.` prefix).
    pub fn validate(&self) -> Result<(), (String, String)> {
        let offset = self.command_time_offset_s;
        if !(offset.is_finite() && offset.abs() <= MAX_COMMAND_OFFSET_S) {
            return Err((
                "command_time_offset_s".into(),
                format!(
                    "must be a number of seconds between -{MAX_COMMAND_OFFSET_S} and {MAX_COMMAND_OFFSET_S}, found {}",
                    crate::error::readable(offset)
                ),
            ));
        }
        if let Some(cutoff) = self.rate_low_pass_hz
            && !(cutoff.is_finite()
                && (MIN_RATE_LOW_PASS_HZ..=MAX_RATE_LOW_PASS_HZ).contains(&cutoff))
        {
            return Err((
                "rate_low_pass_hz".into(),
                format!(
                    "a cutoff frequency, must be between {MIN_RATE_LOW_PASS_HZ} and {MAX_RATE_LOW_PASS_HZ} Hz, found {}",
                    crate::error::readable(cutoff)
                ),
            ));
        }
        if let Some(rate) = self.controller_rate_hz {
            if self.command == CommandLogging::Held {
                return Err((
                    "controller_rate_hz".into(),
                    "a held command changes only at the rows: leave it out".into(),
                ));
            }
            crate::ranges::CONTROLLER_RATE_HZ
                .check(rate)
                .map_err(|message| ("controller_rate_hz".to_string(), message))?;
        }
        Ok(())
    }

    /// Whether this is the default logger (nothing to write in a model file).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Time constant of the body-rate filter, s (0 without one).
    pub fn rate_time_constant_s(&self) -> f64 {
        self.rate_low_pass_hz
            .map(|f| 1.0 / (2.0 * std::f64::consts::PI * f))
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_documented_form_and_defaults() {
        let logger: Logger = serde_json::from_str(
            r#"{"command": "period_mean", "command_time_offset_s": 0.002, "rate_low_pass_hz": 40}"#,
        )
        .unwrap();
        assert_eq!(logger.command, CommandLogging::PeriodMean);
        assert!(logger.validate().is_ok());
        assert!(
            (logger.rate_time_constant_s() - 1.0 / (80.0 * std::f64::consts::PI)).abs() < 1e-15
        );
        let default: Logger = serde_json::from_str("{}").unwrap();
        assert_eq!(default, Logger::default());
        assert_eq!(default.command, CommandLogging::Sample);
        assert!(serde_json::from_str::<Logger>(r#"{"command": "mean"}"#).is_err());
        assert!(serde_json::from_str::<Logger>(r#"{"offset": 1}"#).is_err());
    }

    #[test]
    fn bad_numbers_name_the_field() {
        let far = Logger {
            command_time_offset_s: 2.0,
            ..Logger::default()
        };
        assert_eq!(far.validate().unwrap_err().0, "command_time_offset_s");
        let slow = Logger {
            rate_low_pass_hz: Some(0.0),
            ..Logger::default()
        };
        assert_eq!(slow.validate().unwrap_err().0, "rate_low_pass_hz");
    }
}
