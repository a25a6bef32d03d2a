//! Recordings that cannot be compared with a model, refused before any work rather than reported
//! as physics: nothing moves (a constant recording), no thrust is ever commanded (the vehicle
//! cannot have flown), or there is no measurement noise (the evidence rule measures residuals in
//! units of the noise, which is then undefined); and the bound on the rows of one analysis.

use data::FlightLog;
use physics::{Actuators, NominalModel, ThrustSource};
use sindy::median::median;

use crate::locate::problem::{CHANNEL_NAMES, Problem};

/// What makes a recording degenerate.
#[derive(Clone, Debug, PartialEq)]
pub enum Degeneracy {
    /// Signals the comparison differentiates hold one value on every row (`constant` names every
    /// constant quantity of the recording; at least one of them is compared).
    Constant { constant: Vec<&'static str> },
    /// The thrust the model reads from `column` stays below [`MIN_THRUST_TO_WEIGHT`] of the weight
    /// on every row (`largest`: its largest ratio).
    NoThrust { column: &'static str, largest: f64 },
    /// The noise floor of these channels is below [`NOISE_RESOLUTION`] of their signal.
    NoNoise { channels: Vec<&'static str> },
}

/// The smallest noise floor, relative to the typical size of a channel's weak-form target (the
/// root of its median square), that a channel must have: below it, what the comparison leaves is
/// its own quadrature error (a few parts in 10⁴ of the signal), not measurement noise. Measured on
/// every channel: noise-free simulations of the demo's four configurations 9e-8 to 3e-5; the same
/// flights with their noise 6e-3 to 0.46, and the 30 Neural-Fly flights 3.4e-3 to 0.33 (the bound
/// is ten times above the first and below the last).
pub const NOISE_RESOLUTION: f64 = 3e-4;

/// The thrust, as a share of the weight, that the commands must reach on at least one row: a
/// vehicle whose commanded thrust stays below a tenth of its weight for a whole recording is on the
/// ground, falling, or its thrust column holds something else.
pub const MIN_THRUST_TO_WEIGHT: f64 = 0.1;

/// The most rows one analysis accepts: it holds every row's comparison, candidates and predictions
/// at once (about 8 KB per row, so about 300 MB at this bound). A longer recording is analysed in
/// parts of at most this many rows ([`crate::analyze_in_parts`]).
pub const MAX_ANALYSED_ROWS: usize = 40_000;

/// What the bound rests on, as the refusal says it.
pub const COST_MEASURED: &str = "one analysis holds every row in memory, about 8 KB per row";

impl std::fmt::Display for Degeneracy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Constant { constant } => write!(
                f,
                "degenerate recording, no excitation: {} the same on every row, so nothing moves and there is nothing to compare a model with",
                listed(constant, if constant.len() == 1 { "is" } else { "are" })
            ),
            Self::NoThrust { column, largest } => write!(
                f,
                "degenerate recording, no thrust: the thrust the model reads from {column} stays below {MIN_THRUST_TO_WEIGHT} of the weight on every row (at most {largest:.3}): the vehicle cannot have flown (on the ground, in free fall, or {column} holds something else)"
            ),
            Self::NoNoise { channels } => write!(
                f,
                "degenerate recording, no measurement noise on {} (noise floor below {NOISE_RESOLUTION} of the signal, under the comparison's own accuracy): simulated without noise? The evidence rule measures residuals in units of the noise, so it is undefined here; add measurement noise",
                listed(channels, "")
            ),
        }
    }
}

/// `a, b and c` followed by `verb` (when not empty).
fn listed(items: &[&str], verb: &str) -> String {
    let text = match items {
        [] => String::new(),
        [one] => one.to_string(),
        [head @ .., last] => format!("{} and {last}", head.join(", ")),
    };
    if verb.is_empty() {
        text
    } else {
        format!("{text} {verb}")
    }
}

/// Fails when a signal the comparison differentiates (a velocity component, and a body-rate
/// component when the model predicts torques) is the same on every row.
pub fn check_excitation(log: &FlightLog, model: &NominalModel) -> Result<(), Degeneracy> {
    let component = |rows: &[[f64; 3]], i: usize| constant(rows.iter().map(|r| r[i]));
    let mut found = Vec::new();
    let mut compared = false;
    for (i, name) in ["v_x", "v_y", "v_z"].into_iter().enumerate() {
        if component(&log.velocity, i) {
            found.push(name);
            compared = true;
        }
    }
    for (i, name) in ["w_x", "w_y", "w_z"].into_iter().enumerate() {
        if component(&log.body_rate, i) {
            found.push(name);
            compared |= model.predicts_torque();
        }
    }
    if !compared {
        return Ok(());
    }
    let attitude = (0..4).all(|i| constant(log.quaternion.iter().map(|q| q[i])));
    let position = (0..3).all(|i| component(&log.position, i));
    let thrust = constant(log.thrust_setpoint.iter().copied());
    let motors = log.motor_command.count();
    let pwm = (0..motors).all(|i| constant(log.motor_command.rows().map(|c| c[i])));
    for (is_constant, name) in [
        (position, "p"),
        (attitude, "q"),
        (thrust, "T_sp"),
        (pwm, "pwm"),
    ] {
        if is_constant {
            found.push(name);
        }
    }
    Err(Degeneracy::Constant { constant: found })
}

/// Whether every value of `values` equals the first.
fn constant(mut values: impl Iterator<Item = f64>) -> bool {
    let first = values.next();
    values.all(|v| Some(v) == first)
}

/// Fails when the thrust the model reads from the commands (`commands`, the model's actuator
/// states per row) stays below [`MIN_THRUST_TO_WEIGHT`] of the weight on every row.
pub fn check_thrust(commands: &[Actuators], model: &NominalModel) -> Result<(), Degeneracy> {
    let weight = model.mass_kg * model.gravity_m_s2;
    let largest = commands
        .iter()
        .map(|u| model.wrench(u).thrust / weight)
        .fold(f64::NEG_INFINITY, |a, b| a.max(b));
    // A NaN or infinite thrust is the overflow checks' to report.
    if largest.is_finite() && largest < MIN_THRUST_TO_WEIGHT {
        let column = match model.thrust_source {
            ThrustSource::Mixer => "pwm",
            ThrustSource::ThrustSetpoint => "T_sp",
        };
        return Err(Degeneracy::NoThrust {
            column,
            largest: largest.max(0.0),
        });
    }
    Ok(())
}

/// Fails when a compared channel's noise floor is below [`NOISE_RESOLUTION`] of the typical size
/// of its target (the root of the median square: a few corrupt rows do not make a channel look
/// noise-free, and values that overflow are left to the checks that name them).
pub fn check_noise(problem: &Problem) -> Result<(), Degeneracy> {
    let channels: Vec<&'static str> = (0..problem.channels)
        .filter(|&c| {
            let squares: Vec<f64> = problem.target.iter().map(|t| t[c] * t[c]).collect();
            // No rows: 0, and no noise floor is below 0.
            let typical = median(squares).sqrt();
            typical.is_finite() && problem.noise_floor[c] < NOISE_RESOLUTION * typical
        })
        .map(|c| CHANNEL_NAMES[c])
        .collect();
    if channels.is_empty() {
        Ok(())
    } else {
        Err(Degeneracy::NoNoise { channels })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_read_as_prose() {
        assert_eq!(listed(&["v_x"], "is"), "v_x is");
        assert_eq!(listed(&["v_x", "v_y", "q"], "are"), "v_x, v_y and q are");
        assert_eq!(listed(&["vdot_x", "wdot_z"], ""), "vdot_x and wdot_z");
    }
}
