//! A simulated battery's voltage: it falls as the charge is used and sags under load, so that a
//! vehicle whose thrust map depends on the voltage flies, and logs, a voltage that moves.

use serde::{Deserialize, Serialize};

use crate::error::readable;

/// The highest battery voltage a scenario may give, V (a 24-cell pack).
pub const MAX_BATTERY_V: f64 = 105.0;

/// `V(t, T) = voltage_v − drop_v_per_s · t − sag_v_per_n · T`, `t` from the recording's start and
/// `T` the collective thrust (the load's current through the internal resistance, taken as
/// proportional to the thrust).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Battery {
    /// The unloaded voltage at the recording's start, V.
    pub voltage_v: f64,
    /// How fast the unloaded voltage falls, V/s (optional, 0).
    #[serde(default)]
    pub drop_v_per_s: f64,
    /// How much the voltage sags per newton of collective thrust, V/N (optional, 0).
    #[serde(default)]
    pub sag_v_per_n: f64,
}

impl Battery {
    /// The voltage at time `t` (s from the recording's start) under thrust `thrust_n`.
    pub fn voltage(&self, t: f64, thrust_n: f64) -> f64 {
        self.voltage_v - self.drop_v_per_s * t - self.sag_v_per_n * thrust_n
    }

    /// Checks the numbers, and that the voltage stays above half its start over `span_s` (from the
    /// warm-up's start to the end) under up to `max_thrust_n`; the error names the field.
    pub fn check(&self, span_s: (f64, f64), max_thrust_n: f64) -> Result<(), (String, String)> {
        if !(self.voltage_v > 0.0 && self.voltage_v <= MAX_BATTERY_V) {
            return Err((
                "battery.voltage_v".into(),
                format!(
                    "{} is outside (0, {MAX_BATTERY_V}] V",
                    readable(self.voltage_v)
                ),
            ));
        }
        for (name, value) in [
            ("drop_v_per_s", self.drop_v_per_s),
            ("sag_v_per_n", self.sag_v_per_n),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err((
                    format!("battery.{name}"),
                    format!("{} is outside [0, 1]", readable(value)),
                ));
            }
        }
        let lowest = self.voltage(span_s.1, max_thrust_n);
        if lowest < 0.5 * self.voltage(span_s.0, 0.0) {
            return Err((
                "battery".into(),
                format!(
                    "the voltage falls to {} V at full thrust by the end, below half its start: no flight ends there",
                    readable(lowest)
                ),
            ));
        }
        Ok(())
    }
}
