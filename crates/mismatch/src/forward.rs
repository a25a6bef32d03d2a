//! The model's prediction averaged over each sample interval, with any set of effects.
//!
//! Over the interval between rows k and k+1 the recorded command of row k is held (zero-order hold);
//! a delay shifts that command stream and a motor lag filters it, both evaluated exactly on a fine
//! grid of [`SUBSTEPS`] sub-intervals. Attitude, velocity, height and rate are interpolated linearly
//! between the rows. The mean of the acceleration over an interval is what the velocity change over
//! that interval measures, which is what makes the comparison with a smoothed derivative exact for
//! a correct model (see [`crate::filter`]).

use physics::vector::{Mat3, Vec3};
use physics::{Effects, NominalModel};

use crate::recording::Recording;

/// Sub-intervals per sample interval.
pub const SUBSTEPS: usize = 10;

/// Interval means of the translational and (if the model predicts torques) angular accelerations.
#[derive(Clone, Debug)]
pub struct IntervalPrediction {
    pub translational: Vec<Vec3>,
    pub angular: Option<Vec<Vec3>>,
}

/// Predicts every interval of a recording.
pub fn predict_intervals(
    recording: &Recording,
    model: &NominalModel,
    effects: &Effects,
) -> IntervalPrediction {
    let n = recording.len();
    let actuators = actuator_trace(
        &recording.commands,
        recording.dt,
        model.actuator_count(),
        effects.delay_s(),
        effects.lag_s(),
    );
    let angular_wanted = model.predicts_torque();
    let mut translational = Vec::with_capacity(n - 1);
    let mut angular = Vec::with_capacity(if angular_wanted { n - 1 } else { 0 });
    for k in 0..n - 1 {
        let mut sum_translational = [0.0; 3];
        let mut sum_angular = [0.0; 3];
        for j in 0..SUBSTEPS {
            let s = (j as f64 + 0.5) / SUBSTEPS as f64;
            let rotation = lerp_matrix(&recording.rotation[k], &recording.rotation[k + 1], s);
            let velocity = lerp(recording.velocity[k], recording.velocity[k + 1], s);
            let height = recording.height[k] + s * (recording.height[k + 1] - recording.height[k]);
            let wrench = model.wrench(&actuators[k * SUBSTEPS + j]);
            let a = effects.translational_acceleration(
                model,
                &rotation,
                velocity,
                height,
                wrench.thrust,
            );
            for i in 0..3 {
                sum_translational[i] += a[i];
            }
            if angular_wanted {
                let rate = lerp(recording.body_rate[k], recording.body_rate[k + 1], s);
                let torque = wrench.torque.unwrap_or([0.0; 3]);
                let alpha = effects.angular_acceleration(model, rate, torque);
                for i in 0..3 {
                    sum_angular[i] += alpha[i];
                }
            }
        }
        translational.push(sum_translational.map(|v| v / SUBSTEPS as f64));
        if angular_wanted {
            angular.push(sum_angular.map(|v| v / SUBSTEPS as f64));
        }
    }
    IntervalPrediction {
        translational,
        angular: angular_wanted.then_some(angular),
    }
}

fn lerp(a: Vec3, b: Vec3, s: f64) -> Vec3 {
    [
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
    ]
}

fn lerp_matrix(a: &Mat3, b: &Mat3, s: f64) -> Mat3 {
    [
        lerp(a[0], b[0], s),
        lerp(a[1], b[1], s),
        lerp(a[2], b[2], s),
    ]
}

/// The actuator states at the midpoint of every sub-interval: the held command stream delayed by
/// `delay` seconds (the mean over each sub-interval, so it is continuous in the delay) and passed
/// through a first-order lag of time constant `lag` (exact for a held input).
pub fn actuator_trace(
    commands: &[[f64; 4]],
    dt: f64,
    count: usize,
    delay: f64,
    lag: f64,
) -> Vec<[f64; 4]> {
    let n = commands.len();
    let h = dt / SUBSTEPS as f64;
    let total = (n - 1) * SUBSTEPS;
    let command_at = |index: f64| -> usize { (index.max(0.0) as usize).min(n - 1) };
    let mut out = Vec::with_capacity(total);
    let mut state = commands[0];
    let decay_full = if lag > 0.0 { (-h / lag).exp() } else { 0.0 };
    let decay_half = if lag > 0.0 {
        (-h / (2.0 * lag)).exp()
    } else {
        0.0
    };
    for step in 0..total {
        let start = step as f64 * h - delay;
        let end = start + h;
        let first = (start / dt).floor();
        let boundary = (first + 1.0) * dt;
        let input = if end <= boundary || first < -1.0 {
            commands[command_at(first)]
        } else {
            let weight_first = (boundary - start) / h;
            let a = commands[command_at(first)];
            let b = commands[command_at(first + 1.0)];
            let mut mixed = [0.0; 4];
            for i in 0..count {
                mixed[i] = weight_first * a[i] + (1.0 - weight_first) * b[i];
            }
            mixed
        };
        if lag > 0.0 {
            let mut midpoint = [0.0; 4];
            for i in 0..count {
                midpoint[i] = input[i] + (state[i] - input[i]) * decay_half;
                state[i] = input[i] + (state[i] - input[i]) * decay_full;
            }
            out.push(midpoint);
        } else {
            out.push(input);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delay_shifts_the_held_commands_and_lag_approaches_them() {
        let commands: Vec<[f64; 4]> = (0..6).map(|k| [k as f64, 0.0, 0.0, 0.0]).collect();
        let dt = 0.02;
        let plain = actuator_trace(&commands, dt, 1, 0.0, 0.0);
        assert_eq!(plain[SUBSTEPS * 2 + 3][0], 2.0);
        // Delay of exactly one interval: interval 3 sees command 2.
        let delayed = actuator_trace(&commands, dt, 1, dt, 0.0);
        assert!((delayed[SUBSTEPS * 3 + 5][0] - 2.0).abs() < 1e-12);
        // Half a sub-interval of delay mixes two commands half and half at the switch.
        let half = actuator_trace(&commands, dt, 1, dt / SUBSTEPS as f64 / 2.0, 0.0);
        assert!((half[SUBSTEPS * 2][0] - 1.5).abs() < 1e-9);
        // A lag follows a step monotonically, without overshoot, and reaches 1 − e^(−t/τ).
        let step: Vec<[f64; 4]> = (0..6)
            .map(|k| [if k >= 2 { 1.0 } else { 0.0 }, 0.0, 0.0, 0.0])
            .collect();
        let lagged = actuator_trace(&step, dt, 1, 0.0, 0.05);
        let response: Vec<f64> = lagged[SUBSTEPS * 2..].iter().map(|a| a[0]).collect();
        assert!(response.windows(2).all(|w| w[1] > w[0] && w[1] < 1.0));
        let midpoint = (SUBSTEPS as f64 + 0.5) * dt / SUBSTEPS as f64;
        assert!((response[SUBSTEPS] - (1.0 - (-midpoint / 0.05f64).exp())).abs() < 1e-12);
    }
}
