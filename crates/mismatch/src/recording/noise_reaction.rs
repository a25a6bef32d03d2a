//! The part of a sampled command that reacts to the logged measurement noise and that the vehicle
//! did not feel.
//!
//! A controller `N` times faster than the log reacts, at every control step, to the noise of that
//! step's measurement. A logger that samples the command together with the state logs the command
//! with its reaction to the very noise the row's state carries, but the vehicle held that command
//! for one control step of the `N` in the row: `1 − 1/N` of that reaction is in the log and was
//! never felt. The comparison would read it as command content and attenuate every factor it
//! estimates through the commands.
//!
//! The reaction is identified from the log (a robust regression of the commands' fourth differences
//! on those of the logged rate, attitude, velocity and position); each row's attitude and position
//! noise is estimated by a fixed-interval smoother against the kinematics the log itself holds (the
//! attitude against the integrated rates, the position against the integrated velocities; nothing
//! linked across a gap), which no effect of the library changes. The reaction to the rate and velocity noise stays: no kinematic
//! relation separates it from the motion.

use faer::Mat;
use faer::linalg::solvers::Solve;
use physics::vector::{Mat3, Vec3, mat_mul, transpose, vee};
use physics::{Actuators, CommandLogging, Logger};
use serde::Serialize;
use sindy::median::robust_standard_deviation;
use sindy::sampling::white_noise_sigma_of_fourth_differences;

use crate::recording::Recording;

/// Rows beyond this many robust standard deviations are left out of the regression (command
/// transients).
const TRIM_SIGMAS: f64 = 4.0;
/// A controller at least this many times faster than the log counts as faster than it.
pub const MIN_STEPS_PER_ROW: f64 = 2.0;
/// Fewer rows than this and the reaction is not identified.
const MIN_ROWS: usize = 200;
/// State channels the commands are regressed on: rate, attitude, velocity, position (3 each).
pub const STATES: usize = 12;
/// The smallest error allowed to a predicted velocity change, relative to the velocity's noise.
const VELOCITY_STEP_FLOOR: f64 = 0.02;

/// What was removed from the commands.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NoiseReaction {
    /// Control steps per row, `N`.
    pub steps_per_row: f64,
    /// The unfelt share of the logged reaction, `1 − 1/N`.
    pub unfelt_fraction: f64,
    /// The commands' reaction to each logged state channel, `gains[actuator][state]` (states: rate,
    /// attitude, velocity, position, three axes each).
    pub gains: Vec<[f64; STATES]>,
    /// Whether the reaction to the velocity noise was removed too ([`remove_velocity`]).
    pub velocity: bool,
    /// RMS of the removed part, per actuator command (in the commands' units; the parts come from
    /// independent noises and add in quadrature).
    pub removed_rms: Vec<f64>,
    /// The commands as logged.
    #[serde(skip)]
    pub logged_commands: Vec<Actuators>,
}

/// Control steps per row when the commands are samples of a faster controller taken with the
/// state; `None` otherwise (the vehicle then felt what the log holds, or the log holds no reaction
/// to its own noise).
pub fn steps_per_row(logger: &Logger, dt: f64) -> Option<f64> {
    let rate = logger.controller_rate_hz?;
    let steps = rate * dt;
    let with_the_state = logger.command_time_offset_s.abs() < 0.5 / rate;
    let faster = steps >= MIN_STEPS_PER_ROW;
    (logger.command == CommandLogging::Sample && with_the_state && faster).then_some(steps)
}

/// Removes the unfelt reaction to the logged attitude and position noise from the commands, and
/// records it in `recording.noise_reaction`; returns whether it did.
pub fn remove(recording: &mut Recording, logger: &Logger, actuators: usize) -> bool {
    let Some(steps) = steps_per_row(logger, recording.dt()) else {
        return false;
    };
    if recording.len() < MIN_ROWS {
        return false;
    }
    let states = state_fourth_differences(recording);
    let Some(gains) = reaction_gains(recording, &states, actuators) else {
        return false;
    };
    let mut reaction = NoiseReaction {
        steps_per_row: steps,
        unfelt_fraction: 1.0 - 1.0 / steps,
        gains,
        velocity: false,
        removed_rms: vec![0.0; actuators],
        logged_commands: recording.commands.clone(),
    };
    let attitude = attitude_noise(recording, &states);
    if recording.position_logged {
        let position = position_noise(recording);
        subtract(recording, &mut reaction, &[(3, &attitude), (9, &position)]);
    } else {
        subtract(recording, &mut reaction, &[(3, &attitude)]);
    }
    recording.noise_reaction = Some(reaction);
    true
}

/// Removes the unfelt reaction to the logged velocity noise as well, once a model predicts the
/// velocity: `predicted_change[k]` is the model's velocity change from row `k` to row `k + 1`.
/// The logged change minus the predicted one measures the change of the noise (up to the model's
/// own error, which is why this waits for the identified effects; `prediction_noise` is the standard
/// deviation of the prediction's row-to-row error, per axis). Returns whether it did.
pub fn remove_velocity(
    recording: &mut Recording,
    predicted_change: &[Vec3],
    prediction_noise: Vec3,
) -> bool {
    let Some(mut reaction) = recording.noise_reaction.take() else {
        return false;
    };
    if reaction.velocity || predicted_change.len() + 1 != recording.len() {
        recording.noise_reaction = Some(reaction);
        return false;
    }
    let velocity = &recording.velocity;
    let lengths = interval_lengths(recording);
    let noise = per_axis(|a| {
        let increments: Vec<f64> = (0..recording.len() - 1)
            .map(|k| velocity[k + 1][a] - velocity[k][a] - predicted_change[k][a])
            .collect();
        let logged: Vec<f64> = velocity.iter().map(|v| v[a]).collect();
        let sigma = recording.white_noise_sigma(&logged);
        let step = prediction_noise[a].max(VELOCITY_STEP_FLOOR * sigma);
        smooth_noise(&increments, sigma, step, &lengths)
    });
    subtract(recording, &mut reaction, &[(6, &noise)]);
    reaction.velocity = true;
    recording.noise_reaction = Some(reaction);
    true
}

/// The change of the corrected commands when `noise` is added to the logged body rate: the unfelt
/// reaction to it, less the change of the removed reaction to the attitude noise (whose estimate
/// reads the rates).
pub fn rate_noise_response(
    recording: &Recording,
    reaction: &NoiseReaction,
    noise: &[Vec3],
) -> Vec<Actuators> {
    let states = state_fourth_differences(recording);
    let before = attitude_noise(recording, &states);
    let mut perturbed = recording.clone();
    for (rate, n) in perturbed.body_rate.iter_mut().zip(noise) {
        for a in 0..3 {
            rate[a] += n[a];
        }
    }
    let after = attitude_noise(&perturbed, &states);
    unfelt_response(reaction, recording.len(), |k, a| {
        (noise[k][a], before[k][a] - after[k][a])
    })
}

/// Per row, the unfelt share of the reaction to a rate and an attitude change, `change(row, axis)`
/// giving both: `(1 − 1/N) Σ_a (g_rate,a · rate_a + g_attitude,a · attitude_a)` per actuator.
fn unfelt_response(
    reaction: &NoiseReaction,
    rows: usize,
    change: impl Fn(usize, usize) -> (f64, f64),
) -> Vec<Actuators> {
    (0..rows)
        .map(|k| {
            std::array::from_fn(|i| {
                let Some(gains) = reaction.gains.get(i) else {
                    return 0.0;
                };
                let response: f64 = (0..3)
                    .map(|a| {
                        let (rate, attitude) = change(k, a);
                        gains[a] * rate + gains[3 + a] * attitude
                    })
                    .sum();
                reaction.unfelt_fraction * response
            })
        })
        .collect()
}

/// Subtracts the unfelt share of the reaction to the given noise (each with the index of its first
/// state channel) from the commands, and adds its RMS to the record.
fn subtract(recording: &mut Recording, reaction: &mut NoiseReaction, noises: &[(usize, &[Vec3])]) {
    let actuators = reaction.gains.len();
    let rows = recording.len() as f64;
    let mut squares: Vec<f64> = reaction.removed_rms.iter().map(|r| r * r * rows).collect();
    let mut commands = recording.commands.clone();
    for (k, command) in commands.iter_mut().enumerate() {
        for i in 0..actuators {
            let removed: f64 = noises
                .iter()
                .map(|(first, noise)| {
                    (0..3)
                        .map(|a| reaction.gains[i][first + a] * noise[k][a])
                        .sum::<f64>()
                })
                .sum::<f64>()
                * reaction.unfelt_fraction;
            command[i] -= removed;
            squares[i] += removed * removed;
        }
    }
    recording.set_commands(commands);
    reaction.removed_rms = squares.iter().map(|s| (s / rows).sqrt()).collect();
}

/// The rotation vector from the attitude of row `a` to that of row `b`, in the body frame of `a`
/// (small angles).
fn relative_rotation(a: &Mat3, b: &Mat3) -> Vec3 {
    vee(&mat_mul(&transpose(a), b))
}

/// The fourth-difference weights centred on row `k` (white noise of variance σ² has fourth
/// differences of variance 70 σ²); zero across a gap, where the row takes no part.
fn fourth_difference(recording: &Recording, k: usize) -> [f64; 5] {
    recording
        .sampling
        .fourth_difference_weights(k - 2)
        .unwrap_or([0.0; 5])
}

/// Fourth differences of the twelve logged state channels, centred on rows `2..n−2`.
fn state_fourth_differences(recording: &Recording) -> Vec<[f64; STATES]> {
    (2..recording.len() - 2)
        .map(|k| {
            let weights = fourth_difference(recording, k);
            let fourth = |series: &[Vec3], a: usize| -> f64 {
                (0..5).map(|j| weights[j] * series[k + j - 2][a]).sum()
            };
            let mut row = [0.0; STATES];
            for j in 0..5 {
                let turn =
                    relative_rotation(&recording.rotation[k], &recording.rotation[k + j - 2]);
                for a in 0..3 {
                    row[3 + a] += weights[j] * turn[a];
                }
            }
            for a in 0..3 {
                row[a] = fourth(&recording.body_rate, a);
                row[6 + a] = fourth(&recording.velocity, a);
                if recording.position_logged {
                    row[9 + a] = fourth(&recording.position, a);
                }
            }
            row
        })
        .collect()
}

/// The commands' linear reaction to each state channel (`gains[actuator][state]`), from a
/// regression of fourth differences with the transients trimmed.
fn reaction_gains(
    recording: &Recording,
    states: &[[f64; STATES]],
    actuators: usize,
) -> Option<Vec<[f64; STATES]>> {
    let commands: Vec<Actuators> = (2..recording.len() - 2)
        .map(|k| {
            let weights = fourth_difference(recording, k);
            std::array::from_fn(|i| {
                (0..5)
                    .map(|j| weights[j] * recording.commands[k + j - 2][i])
                    .sum()
            })
        })
        .collect();
    let spans_no_gap: Vec<bool> = (2..recording.len() - 2)
        .map(|k| fourth_difference(recording, k) != [0.0; 5])
        .collect();
    let mut keep = spans_no_gap.clone();
    let mut gains = vec![[0.0; STATES]; actuators];
    for _ in 0..4 {
        gains = least_squares(states, &commands, &keep, actuators)?;
        let residual = |r: usize, i: usize| -> f64 {
            commands[r][i] - (0..STATES).map(|s| gains[i][s] * states[r][s]).sum::<f64>()
        };
        let scales: Vec<f64> = (0..actuators)
            .map(|i| {
                robust_standard_deviation(
                    (0..states.len())
                        .filter(|&r| spans_no_gap[r])
                        .map(|r| residual(r, i)),
                )
            })
            .collect();
        for (r, kept) in keep.iter_mut().enumerate() {
            *kept = spans_no_gap[r]
                && (0..actuators).all(|i| residual(r, i).abs() <= TRIM_SIGMAS * scales[i]);
        }
    }
    Some(gains)
}

fn least_squares(
    states: &[[f64; STATES]],
    commands: &[Actuators],
    keep: &[bool],
    actuators: usize,
) -> Option<Vec<[f64; STATES]>> {
    let mut gram = Mat::<f64>::zeros(STATES, STATES);
    let mut cross = Mat::<f64>::zeros(STATES, actuators);
    for ((x, y), _) in states.iter().zip(commands).zip(keep).filter(|(_, k)| **k) {
        for a in 0..STATES {
            for b in 0..STATES {
                gram[(a, b)] += x[a] * x[b];
            }
            for i in 0..actuators {
                cross[(a, i)] += x[a] * y[i];
            }
        }
    }
    let trace: f64 = (0..STATES).map(|a| gram[(a, a)]).sum();
    if !(trace > 0.0 && trace.is_finite()) {
        return None;
    }
    for a in 0..STATES {
        gram[(a, a)] += 1e-12 * trace;
    }
    let solution = gram.full_piv_lu().solve(&cross);
    let gains: Vec<[f64; STATES]> = (0..actuators)
        .map(|i| std::array::from_fn(|a| solution[(a, i)]))
        .collect();
    gains
        .iter()
        .all(|g| g.iter().all(|v| v.is_finite()))
        .then_some(gains)
}

/// Each row's attitude noise (body frame): the logged turn between rows minus the trapezoid of the
/// logged rates is the change of the noise, up to the rates' own noise. `states`: the fourth
/// differences of the state channels ([`state_fourth_differences`]).
fn attitude_noise(recording: &Recording, states: &[[f64; STATES]]) -> Vec<Vec3> {
    let rows = recording.len();
    let increments: Vec<Vec3> = (0..rows - 1)
        .map(|k| {
            let h = recording.time[k + 1] - recording.time[k];
            let turn = relative_rotation(&recording.rotation[k], &recording.rotation[k + 1]);
            std::array::from_fn(|a| {
                turn[a] - 0.5 * h * (recording.body_rate[k][a] + recording.body_rate[k + 1][a])
            })
        })
        .collect();
    let lengths = interval_lengths(recording);
    per_axis(|a| {
        let (sigma, step) = attitude_smoothing_scales(recording, states, a);
        let series: Vec<f64> = increments.iter().map(|e| e[a]).collect();
        smooth_noise(&series, sigma, step, &lengths)
    })
}

/// For axis `a`, the attitude's white noise (from the fourth differences in `states`) and the error
/// of the turn between rows that the rates' trapezoid leaves (`dt` times the rate's white noise):
/// the scales of the attitude-noise smoother ([`smooth_noise`]).
fn attitude_smoothing_scales(
    recording: &Recording,
    states: &[[f64; STATES]],
    a: usize,
) -> (f64, f64) {
    let fourth: Vec<f64> = states
        .iter()
        .enumerate()
        .filter(|(r, _)| fourth_difference(recording, r + 2) != [0.0; 5])
        .map(|(_, s)| s[3 + a])
        .collect();
    let rate: Vec<f64> = recording.body_rate.iter().map(|w| w[a]).collect();
    (
        white_noise_sigma_of_fourth_differences(&fourth),
        recording.dt() * recording.white_noise_sigma(&rate),
    )
}

/// A draw of the error of each row's attitude-noise estimate ([`attitude_noise`]), from the
/// smoother's posterior, pushed through the unfelt attitude gains to the commands.
pub fn attitude_estimate_error_response(
    recording: &Recording,
    reaction: &NoiseReaction,
    normal: &mut dyn FnMut() -> f64,
) -> Vec<Actuators> {
    let states = state_fourth_differences(recording);
    let lengths = interval_lengths(recording);
    let error = per_axis(|a| {
        let (sigma, step) = attitude_smoothing_scales(recording, &states, a);
        smoothing_error_draw(sigma, step, &lengths, normal)
    });
    unfelt_response(reaction, recording.len(), |k, a| (0.0, error[k][a]))
}

/// Each row's position noise: the logged step minus the trapezoid of the logged velocities.
fn position_noise(recording: &Recording) -> Vec<Vec3> {
    let (p, v) = (&recording.position, &recording.velocity);
    let lengths = interval_lengths(recording);
    per_axis(|a| {
        let series: Vec<f64> = (0..recording.len() - 1)
            .map(|k| {
                let h = recording.time[k + 1] - recording.time[k];
                p[k + 1][a] - p[k][a] - 0.5 * h * (v[k][a] + v[k + 1][a])
            })
            .collect();
        let position: Vec<f64> = p.iter().map(|x| x[a]).collect();
        let velocity: Vec<f64> = v.iter().map(|x| x[a]).collect();
        let step = recording.dt() * recording.white_noise_sigma(&velocity);
        smooth_noise(
            &series,
            recording.white_noise_sigma(&position),
            step,
            &lengths,
        )
    })
}

fn per_axis(mut axis: impl FnMut(usize) -> Vec<f64>) -> Vec<Vec3> {
    let [x, y, z] = [axis(0), axis(1), axis(2)];
    (0..x.len()).map(|k| [x[k], y[k], z[k]]).collect()
}

/// Each row interval's length in nominal intervals, infinite across a gap. An increment's error
/// (the trapezoid of the rates or velocities, the model's prediction) grows with its interval, and
/// across a gap the increment says nothing of the noise: the smoother treats the segments apart.
fn interval_lengths(recording: &Recording) -> Vec<f64> {
    let sampling = &recording.sampling;
    (0..recording.len().saturating_sub(1))
        .map(|k| {
            if sampling.is_gap(k) {
                f64::INFINITY
            } else {
                sampling.interval_at(k) / sampling.interval()
            }
        })
        .collect()
}

/// The white noise `n` (standard deviation `sigma`) whose increments the series `e` measures with
/// errors of standard deviation `step` times each interval's length (`lengths`, in nominal
/// intervals; infinite: no link): minimises `Σ n_k²/σ² + Σ (e_k − (n_{k+1} − n_k))²/(step
/// lengths_k)²` (a tridiagonal system, solved directly). Zero when there is no noise to find.
pub(crate) fn smooth_noise(increments: &[f64], sigma: f64, step: f64, lengths: &[f64]) -> Vec<f64> {
    let rows = increments.len() + 1;
    if !(sigma > 0.0 && sigma.is_finite()) {
        return vec![0.0; rows];
    }
    let (prior, links) = smoother_precisions(sigma, step, lengths);
    let mut diagonal = vec![prior; rows];
    let mut rhs = vec![0.0; rows];
    for (k, (e, link)) in increments.iter().zip(&links).enumerate() {
        diagonal[k] += link;
        diagonal[k + 1] += link;
        rhs[k] -= link * e;
        rhs[k + 1] += link * e;
    }
    // Thomas algorithm; the off-diagonal entries are −links (none after the last row).
    let link = |k: usize| links.get(k).copied().unwrap_or(0.0);
    let mut upper = vec![0.0; rows];
    let mut solution = rhs;
    let mut pivot = diagonal[0];
    upper[0] = -link(0) / pivot;
    solution[0] /= pivot;
    for k in 1..rows {
        pivot = diagonal[k] + link(k - 1) * upper[k - 1];
        upper[k] = -link(k) / pivot;
        solution[k] = (solution[k] + link(k - 1) * solution[k - 1]) / pivot;
    }
    for k in (0..rows - 1).rev() {
        solution[k] -= upper[k] * solution[k + 1];
    }
    solution
}

/// The smoother's precisions: of the noise's prior (`1/σ²`) and of each increment's link
/// (`1/(step lengths_k)²`, the step kept above `10⁻⁶ σ`; zero across a gap).
fn smoother_precisions(sigma: f64, step: f64, lengths: &[f64]) -> (f64, Vec<f64>) {
    let step = step.max(1e-6 * sigma);
    let links = lengths
        .iter()
        .map(|l| {
            let error = step * l;
            1.0 / (error * error)
        })
        .collect();
    (1.0 / (sigma * sigma), links)
}

/// A draw of the error of [`smooth_noise`]'s estimate over the `lengths.len() + 1` rows: Gaussian
/// with the posterior covariance, the inverse of the system's tridiagonal matrix `P` (drawn as
/// `L⁻ᵀ z` with `P = L Lᵀ`). Zero when there is no noise to find.
pub(crate) fn smoothing_error_draw(
    sigma: f64,
    step: f64,
    lengths: &[f64],
    normal: &mut dyn FnMut() -> f64,
) -> Vec<f64> {
    let rows = lengths.len() + 1;
    if !(sigma > 0.0 && sigma.is_finite()) {
        return vec![0.0; rows];
    }
    let (prior, links) = smoother_precisions(sigma, step, lengths);
    let link = |k: usize| links.get(k).copied().unwrap_or(0.0);
    let mut diagonal = vec![0.0; rows];
    let mut lower = vec![0.0; rows];
    for k in 0..rows {
        let (before, previous) = if k > 0 {
            (link(k - 1), lower[k - 1] * lower[k - 1])
        } else {
            (0.0, 0.0)
        };
        diagonal[k] = (prior + (before + link(k)) - previous).sqrt();
        lower[k] = -link(k) / diagonal[k];
    }
    let z: Vec<f64> = (0..rows).map(|_| normal()).collect();
    let mut draw = vec![0.0; rows];
    for k in (0..rows).rev() {
        let next = if k + 1 < rows {
            lower[k] * draw[k + 1]
        } else {
            0.0
        };
        draw[k] = (z[k] - next) / diagonal[k];
    }
    draw
}

#[cfg(test)]
mod tests;
